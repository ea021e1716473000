//! The FMI 3.0 co-simulation API (fmi3Functions.h) over [`Instance`]. Float64 variables only;
//! the other typed accessors accept empty requests and refuse others. Model exchange,
//! scheduled execution, event mode, clocks, FMU state, derivatives, dependencies and
//! configuration mode are not supported: those functions exist (the standard requires every
//! one; importers such as FMPy load them all) and return fmi3Error. Every entry point checks
//! its instance pointer and catches panics.

use std::ffi::{CString, c_char, c_int, c_void};
use std::path::PathBuf;

use crate::ffi::{guard, instance, slice, slice_mut, text};
use crate::instance::{Instance, Mode};

const OK: c_int = 0;
const ERROR: c_int = 3;

type LogMessage = Option<
    unsafe extern "C" fn(
        env: *mut c_void,
        status: c_int,
        category: *const c_char,
        message: *const c_char,
    ),
>;

/// One line to the importer's logger, status Error.
fn log_to(log: LogMessage, env: *mut c_void, message: &str) {
    if let Some(log) = log {
        let message = CString::new(message.replace('\0', " ")).expect("no NUL");
        // SAFETY: the importer's callback, called as fmi3FunctionTypes.h declares it.
        unsafe { log(env, ERROR, c"logStatusError".as_ptr(), message.as_ptr()) };
    }
}

/// Runs `f` on the instance and logs its error: fmi3OK or fmi3Error.
fn with(i: *mut c_void, f: impl FnOnce(&mut Instance) -> Result<(), String>) -> c_int {
    guard(ERROR, || {
        // SAFETY: `i` is null or an instance of ours (the importer's obligation).
        match unsafe { instance(i) } {
            Some(inst) => {
                let r = f(inst);
                if inst.ok(r) { OK } else { ERROR }
            }
            None => ERROR,
        }
    })
}

fn unsupported(i: *mut c_void, what: &str) -> c_int {
    with(i, |_| Err(format!("{what} is not supported")))
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    i: *mut c_void,
    _on: bool,
    _n: usize,
    _categories: *const *const c_char,
) -> c_int {
    with(i, |_| Ok(())) // errors are always logged; there is nothing else to log
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    _name: *const c_char,
    token: *const c_char,
    resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    _event_mode_used: bool,
    _early_return_allowed: bool,
    _required_intermediate: *const u32,
    n_required_intermediate: usize,
    env: *mut c_void,
    log: LogMessage,
    _intermediate_update: *const c_void,
) -> *mut c_void {
    guard(std::ptr::null_mut(), || {
        // SAFETY: the importer passes NUL-terminated strings or null.
        let (token, dir) = unsafe { (text(token), text(resource_path)) };
        let made = if n_required_intermediate > 0 {
            Err("intermediate variables are not supported".to_string())
        } else if dir.is_empty() {
            Err("no resource path: the observer's matrices are in the FMU's resources/".to_string())
        } else {
            let sink: crate::instance::Log = Box::new(move |m: &str| log_to(log, env, m));
            Instance::new(&PathBuf::from(dir), &token, sink)
        };
        match made {
            Ok(inst) => Box::into_raw(Box::new(inst)).cast(),
            Err(e) => {
                log_to(log, env, &format!("fmi3InstantiateCoSimulation: {e}"));
                std::ptr::null_mut()
            }
        }
    })
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    _name: *const c_char,
    _token: *const c_char,
    _resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    env: *mut c_void,
    log: LogMessage,
) -> *mut c_void {
    guard(std::ptr::null_mut(), || {
        log_to(
            log,
            env,
            "model exchange is not supported: this FMU is for co-simulation",
        );
        std::ptr::null_mut()
    })
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    _name: *const c_char,
    _token: *const c_char,
    _resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    env: *mut c_void,
    log: LogMessage,
    _clock_update: *const c_void,
    _lock: *const c_void,
    _unlock: *const c_void,
) -> *mut c_void {
    guard(std::ptr::null_mut(), || {
        log_to(
            log,
            env,
            "scheduled execution is not supported: this FMU is for co-simulation",
        );
        std::ptr::null_mut()
    })
}

/// # Safety
/// `i` is null or an instance of ours, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeInstance(i: *mut c_void) {
    if !i.is_null() {
        // SAFETY: made by Box::into_raw in instantiate; the importer frees it once.
        guard((), || drop(unsafe { Box::from_raw(i.cast::<Instance>()) }));
    }
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    i: *mut c_void,
    _tolerance_defined: bool,
    _tolerance: f64,
    start_time: f64,
    _stop_time_defined: bool,
    _stop_time: f64,
) -> c_int {
    with(i, |inst| inst.enter_initialization(start_time))
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3ExitInitializationMode(i: *mut c_void) -> c_int {
    with(i, Instance::exit_initialization)
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Terminate(i: *mut c_void) -> c_int {
    with(i, Instance::terminate)
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Reset(i: *mut c_void) -> c_int {
    with(i, |inst| {
        inst.reset();
        Ok(())
    })
}

/// # Safety
/// `vr` and `values` hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFloat64(
    i: *mut c_void,
    vr: *const u32,
    nvr: usize,
    values: *mut f64,
    n_values: usize,
) -> c_int {
    with(i, |inst| {
        // SAFETY: the importer passes arrays of the lengths it gives.
        let (vr, values) = unsafe { (slice(vr, nvr), slice_mut(values, n_values)) };
        match (vr, values) {
            (Some(vr), Some(values)) if vr.len() == values.len() => inst.get(vr, values),
            _ => Err("fmi3GetFloat64: null arrays or nValues != nvr".into()),
        }
    })
}

/// # Safety
/// `vr` and `values` hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFloat64(
    i: *mut c_void,
    vr: *const u32,
    nvr: usize,
    values: *const f64,
    n_values: usize,
) -> c_int {
    with(i, |inst| {
        // SAFETY: the importer passes arrays of the lengths it gives.
        let (vr, values) = unsafe { (slice(vr, nvr), slice(values, n_values)) };
        match (vr, values) {
            (Some(vr), Some(values)) if vr.len() == values.len() => inst.set(vr, values),
            _ => Err("fmi3SetFloat64: null arrays or nValues != nvr".into()),
        }
    })
}

/// No variables of the other types: an empty request is fine, any other an error.
macro_rules! no_variables {
    ($($get:ident $set:ident $t:ty;)*) => {$(
        /// # Safety
        /// Called by an FMI importer.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $get(i: *mut c_void, _vr: *const u32, nvr: usize, _values: *mut $t, _n: usize) -> c_int {
            if nvr == 0 { with(i, |_| Ok(())) } else { unsupported(i, stringify!($get)) }
        }
        /// # Safety
        /// Called by an FMI importer.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $set(i: *mut c_void, _vr: *const u32, nvr: usize, _values: *const $t, _n: usize) -> c_int {
            if nvr == 0 { with(i, |_| Ok(())) } else { unsupported(i, stringify!($set)) }
        }
    )*};
}
no_variables! {
    fmi3GetFloat32 fmi3SetFloat32 f32;
    fmi3GetInt8 fmi3SetInt8 i8;
    fmi3GetUInt8 fmi3SetUInt8 u8;
    fmi3GetInt16 fmi3SetInt16 i16;
    fmi3GetUInt16 fmi3SetUInt16 u16;
    fmi3GetInt32 fmi3SetInt32 i32;
    fmi3GetUInt32 fmi3SetUInt32 u32;
    fmi3GetInt64 fmi3SetInt64 i64;
    fmi3GetUInt64 fmi3SetUInt64 u64;
    fmi3GetBoolean fmi3SetBoolean bool;
    fmi3GetString fmi3SetString *const c_char;
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetBinary(
    i: *mut c_void,
    _vr: *const u32,
    nvr: usize,
    _sizes: *mut usize,
    _values: *mut *const u8,
    _n: usize,
) -> c_int {
    if nvr == 0 {
        with(i, |_| Ok(()))
    } else {
        unsupported(i, "fmi3GetBinary")
    }
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetBinary(
    i: *mut c_void,
    _vr: *const u32,
    nvr: usize,
    _sizes: *const usize,
    _values: *const *const u8,
    _n: usize,
) -> c_int {
    if nvr == 0 {
        with(i, |_| Ok(()))
    } else {
        unsupported(i, "fmi3SetBinary")
    }
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetClock(
    i: *mut c_void,
    _vr: *const u32,
    nvr: usize,
    _values: *mut bool,
) -> c_int {
    if nvr == 0 {
        with(i, |_| Ok(()))
    } else {
        unsupported(i, "fmi3GetClock")
    }
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetClock(
    i: *mut c_void,
    _vr: *const u32,
    nvr: usize,
    _values: *const bool,
) -> c_int {
    if nvr == 0 {
        with(i, |_| Ok(()))
    } else {
        unsupported(i, "fmi3SetClock")
    }
}

/// One communication step: z ← F z + G u + K y, refused unless the step is dt.
///
/// # Safety
/// The out-pointers are null or writable.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn fmi3DoStep(
    i: *mut c_void,
    t: f64,
    h: f64,
    _no_set_state_prior: bool,
    event_handling_needed: *mut bool,
    terminate_simulation: *mut bool,
    early_return: *mut bool,
    last_successful_time: *mut f64,
) -> c_int {
    with(i, |inst| {
        let r = inst.do_step(t, h);
        // SAFETY: each is null or writable (the importer's obligation).
        unsafe {
            for flag in [event_handling_needed, terminate_simulation, early_return] {
                if let Some(f) = flag.as_mut() {
                    *f = false;
                }
            }
            if let Some(t) = last_successful_time.as_mut() {
                *t = inst.time();
            }
        }
        r
    })
}

/// # Safety
/// Called by an FMI importer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterStepMode(i: *mut c_void) -> c_int {
    // No event mode: the instance is in step mode as soon as initialization ends.
    with(i, |inst| {
        if inst.mode == Mode::Step {
            Ok(())
        } else {
            Err("fmi3EnterStepMode: no event mode".into())
        }
    })
}

/// Functions of the standard this FMU does not support: fmi3Error with a message.
macro_rules! unsupported {
    ($($name:ident($($arg:ident: $t:ty),*);)*) => {$(
        /// Not supported (fmi3Error).
        ///
        /// # Safety
        /// Called by an FMI importer.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(i: *mut c_void $(, $arg: $t)*) -> c_int {
            $(let _ = $arg;)*
            unsupported(i, stringify!($name))
        }
    )*};
}
unsupported! {
    fmi3EnterEventMode();
    fmi3GetNumberOfVariableDependencies(vr: u32, n: *mut usize);
    fmi3GetVariableDependencies(dependent: u32, element_dependent: *mut usize, independents: *mut u32, element_independents: *mut usize, kinds: *mut c_int, n: usize);
    fmi3GetFMUState(state: *mut *mut c_void);
    fmi3SetFMUState(state: *mut c_void);
    fmi3FreeFMUState(state: *mut *mut c_void);
    fmi3SerializedFMUStateSize(state: *mut c_void, size: *mut usize);
    fmi3SerializeFMUState(state: *mut c_void, bytes: *mut u8, size: usize);
    fmi3DeserializeFMUState(bytes: *const u8, size: usize, state: *mut *mut c_void);
    fmi3GetDirectionalDerivative(unknowns: *const u32, n_unknowns: usize, knowns: *const u32, n_knowns: usize, seed: *const f64, n_seed: usize, sensitivity: *mut f64, n_sensitivity: usize);
    fmi3GetAdjointDerivative(unknowns: *const u32, n_unknowns: usize, knowns: *const u32, n_knowns: usize, seed: *const f64, n_seed: usize, sensitivity: *mut f64, n_sensitivity: usize);
    fmi3EnterConfigurationMode();
    fmi3ExitConfigurationMode();
    fmi3GetIntervalDecimal(vr: *const u32, nvr: usize, intervals: *mut f64, qualifiers: *mut c_int);
    fmi3GetIntervalFraction(vr: *const u32, nvr: usize, counters: *mut u64, resolutions: *mut u64, qualifiers: *mut c_int);
    fmi3GetShiftDecimal(vr: *const u32, nvr: usize, shifts: *mut f64);
    fmi3GetShiftFraction(vr: *const u32, nvr: usize, counters: *mut u64, resolutions: *mut u64);
    fmi3SetIntervalDecimal(vr: *const u32, nvr: usize, intervals: *const f64);
    fmi3SetIntervalFraction(vr: *const u32, nvr: usize, counters: *const u64, resolutions: *const u64);
    fmi3SetShiftDecimal(vr: *const u32, nvr: usize, shifts: *const f64);
    fmi3SetShiftFraction(vr: *const u32, nvr: usize, counters: *const u64, resolutions: *const u64);
    fmi3EvaluateDiscreteStates();
    fmi3UpdateDiscreteStates(update_needed: *mut bool, terminate: *mut bool, nominals_changed: *mut bool, values_changed: *mut bool, next_defined: *mut bool, next_time: *mut f64);
    fmi3EnterContinuousTimeMode();
    fmi3CompletedIntegratorStep(no_set_prior: bool, enter_event_mode: *mut bool, terminate: *mut bool);
    fmi3SetTime(time: f64);
    fmi3SetContinuousStates(x: *const f64, nx: usize);
    fmi3GetContinuousStateDerivatives(derivatives: *mut f64, nx: usize);
    fmi3GetEventIndicators(indicators: *mut f64, ni: usize);
    fmi3GetContinuousStates(x: *mut f64, nx: usize);
    fmi3GetNominalsOfContinuousStates(nominals: *mut f64, nx: usize);
    fmi3GetNumberOfEventIndicators(n: *mut usize);
    fmi3GetNumberOfContinuousStates(n: *mut usize);
    fmi3GetOutputDerivatives(vr: *const u32, nvr: usize, orders: *const i32, values: *mut f64, n_values: usize);
    fmi3ActivateModelPartition(clock: u32, time: f64);
}
