//! An FMU read as an archive, without loading its library: its FMI version, the co-simulation
//! model identifier, whether a binary for this platform is there, and its variables. Every
//! refusal is one line naming the file and the reason.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;

use fmi::schema::fmi2::Initial as I2;
use fmi::schema::fmi2::{Causality as C2, Fmi2ModelDescription, ScalarVariableElement};
use fmi::schema::fmi3::{
    AbstractVariableTrait, ArrayableVariableTrait, Causality as C3, Fmi3ModelDescription,
    Initial as I3, InitializableVariableTrait, Variable,
};
use fmi::schema::minimal::MinModelDescription;
use fmi::schema::traits::FmiModelDescription;
use scenario::untrusted::quoted;

pub use crate::version::Version;

/// What a variable is for, in the words both standards share.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
    Local,
    Independent,
    Other,
}

impl Causality {
    pub fn name(self) -> &'static str {
        match self {
            Causality::Parameter => "a parameter",
            Causality::CalculatedParameter => "a calculated parameter",
            Causality::Input => "an input",
            Causality::Output => "an output",
            Causality::Local => "a local variable",
            Causality::Independent => "the independent variable",
            Causality::Other => "a structural parameter",
        }
    }
}

/// The value types the plant can exchange.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Type {
    /// FMI 2 Real, FMI 3 Float64.
    Real,
    /// FMI 2 Integer, FMI 3 Int32.
    Integer,
    Boolean,
    /// Anything else (named as the FMU's description does).
    Other(&'static str),
}

impl Type {
    pub fn name(self, v: Version) -> &'static str {
        match (self, v) {
            (Type::Real, Version::Two) => "Real",
            (Type::Real, Version::Three) => "Float64",
            (Type::Integer, Version::Two) => "Integer",
            (Type::Integer, Version::Three) => "Int32",
            (Type::Boolean, _) => "Boolean",
            (Type::Other(s), _) => s,
        }
    }
}

/// One variable of the FMU.
#[derive(Debug, Clone)]
pub struct Var {
    pub vr: u32,
    pub causality: Causality,
    pub ty: Type,
    /// An array variable (FMI 3 dimensions): not exchanged as a scalar.
    pub array: bool,
    /// Its start value may be set before initialisation (initial = exact or approx, or a
    /// parameter or an input): a state that may be started anywhere.
    pub settable_start: bool,
}

/// Whether a start value may be set (FMI 2.0 §2.2.7, FMI 3.0 §2.4.7.4): initial exact or
/// approx; without `initial`, a parameter's default is exact and an input has a start value;
/// an output's or a local variable's default is calculated.
fn settable(initial_exact_or_approx: Option<bool>, causality: Causality) -> bool {
    initial_exact_or_approx.unwrap_or(matches!(causality, Causality::Parameter | Causality::Input))
}

/// An FMU's description, as far as the plant needs it.
#[derive(Debug, Clone)]
pub struct Fmu {
    pub version: Version,
    pub model_identifier: String,
    pub vars: BTreeMap<String, Var>,
    /// The library embeds Python: the first `Py…` symbol it needs from its host.
    pub python: Option<String>,
}

/// Where this platform's binary sits in an FMU of `version`.
pub fn binary_path(version: Version, model_identifier: &str) -> String {
    let platform = match version {
        Version::Two => "linux64",
        Version::Three => "x86_64-linux",
    };
    format!("binaries/{platform}/{model_identifier}.so")
}

/// The most an FMU's archive may unpack to (its libraries and resources), bytes.
pub const MAX_UNPACKED: u64 = 4 << 30;
/// The longest `modelDescription.xml` read, bytes (a large model's is a few MB).
pub const MAX_DESCRIPTION: u64 = 64 << 20;

/// The most entries an FMU's archive may hold (a large FMU has hundreds).
pub const MAX_ENTRIES: usize = 10_000;

/// Reads and checks the archive at `path`. What the run extracts is checked here first (the run
/// reads the archive with this before it extracts): at most [`MAX_ENTRIES`] entries, no symbolic
/// link (a link at the library's path would load a host file) and no setuid/setgid mode, and
/// the bytes the entries actually inflate to — counted, not their declared sizes — at most
/// [`MAX_UNPACKED`].
// one job: one FMU archive read with its bounds, each checked where its bytes come.
pub fn read(path: &Path) -> Result<Fmu, String> {
    let at = |why: String| format!("{}: {why}", path.display());
    let file = std::fs::File::open(path).map_err(|e| at(format!("cannot open: {e}")))?;
    let mut zip = zip::ZipArchive::new(file)
        .map_err(|e| at(format!("not an FMU: not a zip archive ({e})")))?;
    if zip.len() > MAX_ENTRIES {
        return Err(at(format!(
            "holds {} entries, more than the {MAX_ENTRIES} an FMU plant may",
            zip.len()
        )));
    }
    for i in 0..zip.len() {
        let f = zip
            .by_index_raw(i)
            .map_err(|e| at(format!("entry {}: {e}", i + 1)))?;
        let mode = f.unix_mode().unwrap_or(0);
        if mode & 0o170000 == 0o120000 {
            return Err(at(format!(
                "entry {} is a symbolic link: an FMU plant's archive holds files only",
                quoted(f.name())
            )));
        }
        if mode & 0o6000 != 0 {
            return Err(at(format!(
                "entry {} has the setuid or setgid bit ({mode:o}): refused",
                quoted(f.name())
            )));
        }
    }
    // The run extracts the whole archive: what it unpacks to is bounded before anything is, by
    // inflating every entry here (a declared size can lie; the CRC does not bound it).
    let mut unpacked = 0u64;
    for i in 0..zip.len() {
        let mut f = zip
            .by_index(i)
            .map_err(|e| at(format!("entry {}: {e}", i + 1)))?;
        let left = MAX_UNPACKED - unpacked;
        let n = std::io::copy(&mut (&mut f).take(left + 1), &mut std::io::sink())
            .map_err(|e| at(format!("entry {}: {e}", quoted(f.name()))))?;
        unpacked += n;
        if n > left {
            return Err(at(format!(
                "unpacks to more than the {MAX_UNPACKED} bytes an FMU plant may (entry {} alone inflates past it)",
                quoted(f.name())
            )));
        }
    }
    let mut xml = String::new();
    zip.by_name("modelDescription.xml")
        .map_err(|_| at("not an FMU: no modelDescription.xml in the archive".into()))?
        .take(MAX_DESCRIPTION + 1)
        .read_to_string(&mut xml)
        .map_err(|e| at(format!("modelDescription.xml: {e}")))?;
    if xml.len() as u64 > MAX_DESCRIPTION {
        return Err(at(format!(
            "modelDescription.xml is longer than {MAX_DESCRIPTION} bytes"
        )));
    }
    let min = MinModelDescription::deserialize(&xml).map_err(|e| {
        at(format!(
            "modelDescription.xml: {}",
            first_line(&e.to_string())
        ))
    })?;
    let version = match min.fmi_version.split('.').next() {
        Some("2") => Version::Two,
        Some("3") => Version::Three,
        _ => {
            return Err(at(format!(
                "FMI version {} is not supported (FMI 2.0 and 3.0 co-simulation are)",
                min.fmi_version
            )));
        }
    };
    let fmu = match version {
        Version::Two => from_fmi2(&xml).map_err(at)?,
        Version::Three => from_fmi3(&xml).map_err(at)?,
    };
    // The library is binaries/<platform>/<modelIdentifier>.so inside the extraction: the
    // identifier must be a plain file name, so the path cannot leave it.
    let id = &fmu.model_identifier;
    if id.is_empty()
        || id.starts_with('.')
        || !id
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.')
    {
        return Err(at(format!(
            "modelIdentifier {} is not a plain file name (letters, digits, _ - .): refused",
            quoted(id)
        )));
    }
    let binary = binary_path(version, &fmu.model_identifier);
    if zip.index_for_name(&binary).is_none() {
        let present: Vec<String> = zip
            .file_names()
            .filter(|n| n.starts_with("binaries/") && !n.ends_with('/'))
            .map(str::to_string)
            .collect();
        let has = if present.is_empty() {
            "none (a source-only FMU is not compiled here)".to_string()
        } else {
            present.join(", ")
        };
        return Err(at(format!(
            "no binary for this platform: {binary} is not in the archive (binaries: {has})"
        )));
    }
    let mut library = Vec::new();
    zip.by_name(&binary)
        .and_then(|f| {
            f.take(MAX_UNPACKED)
                .read_to_end(&mut library)
                .map_err(Into::into)
        })
        .map_err(|e| at(format!("{binary}: {e}")))?;
    if let Some(why) = crate::library::problem(&binary, &library, version) {
        return Err(at(why));
    }
    Ok(Fmu {
        python: crate::python::needs(&library),
        ..fmu
    })
}

fn first_line(s: &str) -> &str {
    s.lines().next().unwrap_or(s)
}

fn no_cs(me: bool) -> String {
    if me {
        "model exchange only: the plant needs an FMU for co-simulation (model exchange, which needs our own integrator, is not supported)".into()
    } else {
        "no co-simulation interface in modelDescription.xml".into()
    }
}

fn from_fmi2(xml: &str) -> Result<Fmu, String> {
    let md = <Fmi2ModelDescription as FmiModelDescription>::deserialize(xml).map_err(|e| {
        format!(
            "modelDescription.xml (FMI 2.0): {}",
            first_line(&e.to_string())
        )
    })?;
    let Some(cs) = &md.co_simulation else {
        return Err(no_cs(md.model_exchange.is_some()));
    };
    let mut vars = BTreeMap::new();
    for v in md.get_model_variables() {
        let causality = match v.causality {
            C2::Parameter => Causality::Parameter,
            C2::CalculatedParameter => Causality::CalculatedParameter,
            C2::Input => Causality::Input,
            C2::Output => Causality::Output,
            C2::Local => Causality::Local,
            C2::Independent => Causality::Independent,
        };
        let ty = match v.elem {
            ScalarVariableElement::Real(_) => Type::Real,
            ScalarVariableElement::Integer(_) => Type::Integer,
            ScalarVariableElement::Boolean(_) => Type::Boolean,
            ScalarVariableElement::String => Type::Other("String"),
            ScalarVariableElement::Enumeration => Type::Other("Enumeration"),
        };
        let initial = v
            .initial
            .as_ref()
            .map(|i| matches!(i, I2::Exact | I2::Approx));
        vars.insert(
            v.name.clone(),
            Var {
                vr: v.value_reference,
                causality,
                ty,
                array: false,
                settable_start: settable(initial, causality),
            },
        );
    }
    Ok(Fmu {
        version: Version::Two,
        model_identifier: cs.model_identifier.clone(),
        vars,
        python: None,
    })
}

fn from_fmi3(xml: &str) -> Result<Fmu, String> {
    let md = <Fmi3ModelDescription as FmiModelDescription>::deserialize(xml).map_err(|e| {
        format!(
            "modelDescription.xml (FMI 3.0): {}",
            first_line(&e.to_string())
        )
    })?;
    let Some(cs) = &md.co_simulation else {
        return Err(no_cs(md.model_exchange.is_some()));
    };
    let mut vars = BTreeMap::new();
    for v in &md.model_variables.variables {
        // Its type, and the variable as the traits every kind shares (a Clock has no dimensions).
        fn of<T: ArrayableVariableTrait>(
            ty: Type,
            x: &T,
        ) -> (Type, &dyn AbstractVariableTrait, bool) {
            (ty, x, !x.dimensions().is_empty())
        }
        let (ty, a, array) = match v {
            Variable::Float64(x) => of(Type::Real, x),
            Variable::Int32(x) => of(Type::Integer, x),
            Variable::Boolean(x) => of(Type::Boolean, x),
            Variable::Float32(x) => of(Type::Other("Float32"), x),
            Variable::Int8(x) => of(Type::Other("Int8"), x),
            Variable::UInt8(x) => of(Type::Other("UInt8"), x),
            Variable::Int16(x) => of(Type::Other("Int16"), x),
            Variable::UInt16(x) => of(Type::Other("UInt16"), x),
            Variable::UInt32(x) => of(Type::Other("UInt32"), x),
            Variable::Int64(x) => of(Type::Other("Int64"), x),
            Variable::UInt64(x) => of(Type::Other("UInt64"), x),
            Variable::String(x) => of(Type::Other("String"), x),
            Variable::Binary(x) => of(Type::Other("Binary"), x),
            Variable::Clock(x) => (Type::Other("Clock"), x as &dyn AbstractVariableTrait, false),
        };
        let causality = match a.causality() {
            C3::Parameter => Causality::Parameter,
            C3::CalculatedParameter => Causality::CalculatedParameter,
            C3::Input => Causality::Input,
            C3::Output => Causality::Output,
            C3::Local => Causality::Local,
            C3::Independent => Causality::Independent,
            _ => Causality::Other,
        };
        // Only a Float64 is ever a state; its `initial` decides whether it may be started.
        let initial = match v {
            Variable::Float64(x) => x.initial().map(|i| matches!(i, I3::Exact | I3::Approx)),
            _ => None,
        };
        vars.insert(
            a.name().to_string(),
            Var {
                vr: a.value_reference(),
                causality,
                ty,
                array,
                settable_start: settable(initial, causality),
            },
        );
    }
    Ok(Fmu {
        version: Version::Three,
        model_identifier: cs.model_identifier.clone(),
        vars,
        python: None,
    })
}
