/* Test FMUs (issue 22): writes a model's modelDescription.xml (FMI 2.0 or 3.0 co-simulation)
 * from its variable table, so the table in the model's C file is the only place a variable is
 * declared. build.sh links this with one model: `describe 2 > modelDescription.xml`.
 *
 * Variables: `time` (independent, value reference 0), then MODEL_VARS[k] with value reference
 * k + 1 (FMI 2 index k + 2). Parameters: fixed, initial exact; inputs: continuous with a start
 * value; outputs: continuous, initial calculated, listed as outputs and initial unknowns. */
#include <stdio.h>
#include <string.h>

#include "model.h"

static void attr(const char *name, const char *value) {
    printf(" %s=\"", name);
    for (const char *c = value; *c; c++) {
        switch (*c) {
        case '&': fputs("&amp;", stdout); break;
        case '<': fputs("&lt;", stdout); break;
        case '>': fputs("&gt;", stdout); break;
        case '"': fputs("&quot;", stdout); break;
        default: putchar(*c);
        }
    }
    putchar('"');
}

static void header(int fmi) {
    printf("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<fmiModelDescription");
    attr("fmiVersion", fmi == 2 ? "2.0" : "3.0");
    attr("modelName", MODEL_IDENTIFIER);
    attr(fmi == 2 ? "guid" : "instantiationToken", MODEL_TOKEN);
    attr("description", MODEL_DESCRIPTION);
    attr("generationTool", "uio-observers fmu/testfmus");
    attr("variableNamingConvention", "flat");
    if (fmi == 2) attr("numberOfEventIndicators", "0");
    printf(">\n  <CoSimulation");
    attr("modelIdentifier", MODEL_IDENTIFIER);
    attr("canHandleVariableCommunicationStepSize", MODEL_VARIABLE_STEP ? "true" : "false");
    if (fmi == 2) attr("canNotUseMemoryManagementFunctions", "true");
    printf("/>\n  <ModelVariables>\n");
}

static void variable2(unsigned vr, const ModelVar *v) {
    printf("    <ScalarVariable");
    attr("name", v ? v->name : "time");
    printf(" valueReference=\"%u\"", vr);
    if (v && v->description[0]) attr("description", v->description);
    if (!v) {
        printf(" causality=\"independent\" variability=\"continuous\"><Real/>");
    } else if (v->causality == PARAMETER) {
        printf(" causality=\"parameter\" variability=\"fixed\" initial=\"exact\">"
               "<Real start=\"%.17g\"/>", v->start);
    } else if (v->causality == INPUT) {
        printf(" causality=\"input\" variability=\"continuous\"><Real start=\"%.17g\"/>", v->start);
    } else if (v->causality == STATE) {
        printf(" causality=\"output\" variability=\"continuous\" initial=\"exact\">"
               "<Real start=\"%.17g\"/>", v->start);
    } else {
        printf(" causality=\"output\" variability=\"continuous\" initial=\"calculated\"><Real/>");
    }
    printf("</ScalarVariable>\n");
}

static void variable3(unsigned vr, const ModelVar *v) {
    printf("    <Float64");
    attr("name", v ? v->name : "time");
    printf(" valueReference=\"%u\"", vr);
    if (v && v->description[0]) attr("description", v->description);
    if (!v)
        printf(" causality=\"independent\" variability=\"continuous\"");
    else if (v->causality == PARAMETER)
        printf(" causality=\"parameter\" variability=\"fixed\" initial=\"exact\" start=\"%.17g\"",
               v->start);
    else if (v->causality == INPUT)
        printf(" causality=\"input\" variability=\"continuous\" start=\"%.17g\"", v->start);
    else if (v->causality == STATE)
        printf(" causality=\"output\" variability=\"continuous\" initial=\"exact\" start=\"%.17g\"",
               v->start);
    else
        printf(" causality=\"output\" variability=\"continuous\" initial=\"calculated\"");
    printf("/>\n");
}

int main(int argc, char **argv) {
    int fmi = argc == 2 && strcmp(argv[1], "2") == 0 ? 2
            : argc == 2 && strcmp(argv[1], "3") == 0 ? 3 : 0;
    if (!fmi) {
        fprintf(stderr, "usage: %s 2|3 > modelDescription.xml\n", argv[0]);
        return 2;
    }
    header(fmi);
    (fmi == 2 ? variable2 : variable3)(0, NULL);
    for (size_t k = 0; k < MODEL_NV; k++) (fmi == 2 ? variable2 : variable3)(k + 1, &MODEL_VARS[k]);
    printf("  </ModelVariables>\n  <ModelStructure>\n");
    const char *kinds2[] = { "Outputs", "InitialUnknowns" }, *kinds3[] = { "Output", "InitialUnknown" };
    for (int kind = 0; kind < 2; kind++) {
        if (fmi == 2) printf("    <%s>\n", kinds2[kind]);
        for (size_t k = 0; k < MODEL_NV; k++) {
            /* states are outputs too; an initial unknown only when calculated (not exact) */
            Causality c = MODEL_VARS[k].causality;
            if (!(c == OUTPUT || (c == STATE && kind == 0))) continue;
            if (fmi == 2) printf("      <Unknown index=\"%zu\"/>\n", k + 2);
            else printf("    <%s valueReference=\"%zu\"/>\n", kinds3[kind], k + 1);
        }
        if (fmi == 2) printf("    </%s>\n", kinds2[kind]);
    }
    printf("  </ModelStructure>\n</fmiModelDescription>\n");
    return ferror(stdout) ? 1 : 0;
}
