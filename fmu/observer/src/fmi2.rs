//! The FMI 2.0 co-simulation API (fmi2Functions.h) over [`Instance`]. Real variables only;
//! Integer, Boolean and String accessors accept empty requests and refuse others; FMU state,
//! directional derivatives, input derivatives and asynchronous steps are not supported
//! (fmi2Error). Every entry point checks its instance pointer and catches panics.

use std::ffi::{CString, c_char, c_int, c_void};

use crate::ffi::{guard, instance, slice, slice_mut, text, uri_path};
use crate::instance::Instance;

const OK: c_int = 0;
const ERROR: c_int = 3;
const CO_SIMULATION: c_int = 1;
const LAST_SUCCESSFUL_TIME: c_int = 2;

type Logger = Option<
    unsafe extern "C" fn(
        env: *mut c_void,
        name: *const c_char,
        status: c_int,
        category: *const c_char,
        message: *const c_char,
        ...
    ),
>;

/// fmi2CallbackFunctions.
#[repr(C)]
pub struct CallbackFunctions {
    logger: Logger,
    allocate_memory: *const c_void,
    free_memory: *const c_void,
    step_finished: *const c_void,
    component_environment: *mut c_void,
}

/// One line to the importer's logger, status Error (as the argument of a "%s" format, so a
/// `%` in it is printed, not interpreted).
fn log_to(log: Logger, env: *mut c_void, name: &CString, message: &str) {
    if let Some(log) = log {
        let message = CString::new(message.replace('\0', " ")).expect("no NUL");
        // SAFETY: the importer's callback, called as fmi2FunctionTypes.h declares it.
        unsafe {
            log(
                env,
                name.as_ptr(),
                ERROR,
                c"logStatusError".as_ptr(),
                c"%s".as_ptr(),
                message.as_ptr(),
            )
        };
    }
}

/// Runs `f` on the instance and logs its error: fmi2OK or fmi2Error.
fn with(c: *mut c_void, f: impl FnOnce(&mut Instance) -> Result<(), String>) -> c_int {
    guard(ERROR, || {
        // SAFETY: `c` is null or an instance of ours (the importer's obligation).
        match unsafe { instance(c) } {
            Some(inst) => {
                let r = f(inst);
                if inst.ok(r) { OK } else { ERROR }
            }
            None => ERROR,
        }
    })
}

fn unsupported(c: *mut c_void, what: &str) -> c_int {
    with(c, |_| Err(format!("{what} is not supported")))
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: *mut c_void,
    _on: c_int,
    _n: usize,
    _categories: *const *const c_char,
) -> c_int {
    with(c, |_| Ok(())) // errors are always logged; there is nothing else to log
}

/// # Safety
/// Called by an FMI importer; `functions` is null or valid.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    name: *const c_char,
    fmu_type: c_int,
    guid: *const c_char,
    resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: c_int,
    _logging_on: c_int,
) -> *mut c_void {
    guard(std::ptr::null_mut(), || {
        // SAFETY: the importer passes NUL-terminated strings (or null) and valid callbacks.
        let (name, guid, location, functions) = unsafe {
            (
                text(name),
                text(guid),
                text(resource_location),
                functions.as_ref(),
            )
        };
        let Some(functions) = functions else {
            return std::ptr::null_mut();
        };
        let (log, env) = (functions.logger, functions.component_environment);
        let name = CString::new(name.replace('\0', " ")).expect("no NUL");
        let made = if fmu_type != CO_SIMULATION {
            Err("model exchange is not supported: this FMU is for co-simulation".to_string())
        } else {
            uri_path(&location).and_then(|dir| {
                let own = name.clone();
                Instance::new(
                    &dir,
                    &guid,
                    Box::new(move |m: &str| log_to(log, env, &own, m)),
                )
            })
        };
        match made {
            Ok(inst) => Box::into_raw(Box::new(inst)).cast(),
            Err(e) => {
                log_to(log, env, &name, &format!("fmi2Instantiate: {e}"));
                std::ptr::null_mut()
            }
        }
    })
}

/// # Safety
/// `c` is null or an instance of ours, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    if !c.is_null() {
        // SAFETY: made by Box::into_raw in fmi2Instantiate; the importer frees it once.
        guard((), || drop(unsafe { Box::from_raw(c.cast::<Instance>()) }));
    }
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: *mut c_void,
    _tolerance_defined: c_int,
    _tolerance: f64,
    start_time: f64,
    _stop_time_defined: c_int,
    _stop_time: f64,
) -> c_int {
    with(c, |inst| {
        if inst.mode != crate::instance::Mode::Instantiated {
            return Err("fmi2SetupExperiment: only after instantiation or reset".into());
        }
        inst.start_time = start_time;
        Ok(())
    })
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: *mut c_void) -> c_int {
    with(c, |inst| inst.enter_initialization(inst.start_time))
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> c_int {
    with(c, Instance::exit_initialization)
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: *mut c_void) -> c_int {
    with(c, Instance::terminate)
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: *mut c_void) -> c_int {
    with(c, |inst| {
        inst.reset();
        Ok(())
    })
}

/// # Safety
/// `vr` and `values` hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: *mut c_void,
    vr: *const u32,
    nvr: usize,
    values: *mut f64,
) -> c_int {
    with(c, |inst| {
        // SAFETY: the importer passes arrays of nvr elements.
        match unsafe { (slice(vr, nvr), slice_mut(values, nvr)) } {
            (Some(vr), Some(values)) => inst.get(vr, values),
            _ => Err("fmi2GetReal: null arrays".into()),
        }
    })
}

/// # Safety
/// `vr` and `values` hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(
    c: *mut c_void,
    vr: *const u32,
    nvr: usize,
    values: *const f64,
) -> c_int {
    with(c, |inst| {
        // SAFETY: the importer passes arrays of nvr elements.
        match unsafe { (slice(vr, nvr), slice(values, nvr)) } {
            (Some(vr), Some(values)) => inst.set(vr, values),
            _ => Err("fmi2SetReal: null arrays".into()),
        }
    })
}

/// No Integer, Boolean or String variables: an empty request is fine, any other an error.
macro_rules! no_variables {
    ($($get:ident $set:ident $t:ty;)*) => {$(
        /// # Safety
        /// Called by an FMI importer.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $get(c: *mut c_void, _vr: *const u32, nvr: usize, _values: *mut $t) -> c_int {
            if nvr == 0 { with(c, |_| Ok(())) } else { unsupported(c, stringify!($get)) }
        }
        /// # Safety
        /// Called by an FMI importer.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $set(c: *mut c_void, _vr: *const u32, nvr: usize, _values: *const $t) -> c_int {
            if nvr == 0 { with(c, |_| Ok(())) } else { unsupported(c, stringify!($set)) }
        }
    )*};
}
no_variables! {
    fmi2GetInteger fmi2SetInteger c_int;
    fmi2GetBoolean fmi2SetBoolean c_int;
    fmi2GetString fmi2SetString *const c_char;
}

/// One communication step: z ← F z + G u + K y, refused unless the step is dt.
///
/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: *mut c_void,
    t: f64,
    h: f64,
    _no_set_state_prior: c_int,
) -> c_int {
    with(c, |inst| inst.do_step(t, h))
}

/// # Safety
/// `value` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(c: *mut c_void, kind: c_int, value: *mut f64) -> c_int {
    with(c, |inst| {
        // SAFETY: null or writable (the importer's obligation).
        match (kind, unsafe { value.as_mut() }) {
            (LAST_SUCCESSFUL_TIME, Some(v)) => {
                *v = inst.time();
                Ok(())
            }
            _ => Err("fmi2GetRealStatus: only fmi2LastSuccessfulTime is supported".into()),
        }
    })
}

/// Functions of the standard this FMU does not support: fmi2Error with a message.
macro_rules! unsupported {
    ($($name:ident($($arg:ident: $t:ty),*);)*) => {$(
        /// Not supported (fmi2Error).
        ///
        /// # Safety
        /// Called by an FMI importer.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(c: *mut c_void $(, $arg: $t)*) -> c_int {
            $(let _ = $arg;)*
            unsupported(c, stringify!($name))
        }
    )*};
}
unsupported! {
    fmi2GetFMUstate(state: *mut *mut c_void);
    fmi2SetFMUstate(state: *mut c_void);
    fmi2FreeFMUstate(state: *mut *mut c_void);
    fmi2SerializedFMUstateSize(state: *mut c_void, size: *mut usize);
    fmi2SerializeFMUstate(state: *mut c_void, bytes: *mut c_char, size: usize);
    fmi2DeSerializeFMUstate(bytes: *const c_char, size: usize, state: *mut *mut c_void);
    fmi2GetDirectionalDerivative(unknowns: *const u32, n_unknowns: usize, knowns: *const u32, n_knowns: usize, dv_known: *const f64, dv_unknown: *mut f64);
    fmi2SetRealInputDerivatives(vr: *const u32, nvr: usize, order: *const c_int, values: *const f64);
    fmi2GetRealOutputDerivatives(vr: *const u32, nvr: usize, order: *const c_int, values: *mut f64);
    fmi2CancelStep();
    fmi2GetStatus(kind: c_int, value: *mut c_int);
    fmi2GetIntegerStatus(kind: c_int, value: *mut c_int);
    fmi2GetBooleanStatus(kind: c_int, value: *mut c_int);
    fmi2GetStringStatus(kind: c_int, value: *mut *const c_char);
}
