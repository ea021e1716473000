//! An FMI 2.0 co-simulation instance: the `fmi` crate extracts the archive and loads the
//! library's functions; the instance is made here, with our own callbacks, so that what the
//! FMU logs is kept whatever it passes. (The crate's own logger reads `category` without a NULL
//! check, and pythonfmu logs with a NULL category: its first message killed the process with
//! SIGSEGV, before anything was said.)
//!
//! After a call returns fmi2Fatal nothing more is called, not even fmi2FreeInstance (FMI 2.0
//! §2.1.3: "the model computations are irreparably corrupted"): pythonfmu's instance crashes
//! when freed after a Python exception.

use std::ffi::{CStr, CString, c_char};

use fmi::fmi2::binding as b;
use fmi::fmi2::import::Fmi2Import;
use fmi::traits::FmiImport as _;

use crate::log_capture;

/// Some instance returned fmi2Fatal in this process.
static FATAL: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Whether an FMU's call returned fmi2Fatal: then the process must end without running the
/// exit handlers of the libraries the FMU loaded (numpy's bundled libgfortran freed corrupted
/// memory at exit after a Python exception in pythonfmu's doStep: SIGABRT).
pub fn fatal() -> bool {
    FATAL.load(std::sync::atomic::Ordering::Relaxed)
}

unsafe extern "C" {
    /// c/fmi2_logger.c: formats the message and calls [`uio_fmi2_log`].
    fn uio_fmi2_logger(
        env: b::fmi2ComponentEnvironment,
        instance: b::fmi2String,
        status: b::fmi2Status,
        category: b::fmi2String,
        message: b::fmi2String,
        ...
    );
}

/// What c/fmi2_logger.c hands over: one formatted message. Any pointer may be NULL.
#[unsafe(no_mangle)]
extern "C" fn uio_fmi2_log(
    instance: *const c_char,
    status: std::ffi::c_int,
    category: *const c_char,
    text: *const c_char,
) {
    // SAFETY: each is NULL or a NUL-terminated string that lives for this call.
    let s = |p: *const c_char| {
        if p.is_null() {
            String::new()
        } else {
            unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
        }
    };
    let level = match status as b::fmi2Status {
        b::fmi2Status_fmi2OK => log::Level::Info,
        b::fmi2Status_fmi2Warning | b::fmi2Status_fmi2Discard => log::Level::Warn,
        _ => log::Level::Error,
    };
    log_capture::record(&s(instance), level, &s(category), &s(text));
}

fn status_name(s: b::fmi2Status) -> &'static str {
    match s {
        b::fmi2Status_fmi2OK => "OK",
        b::fmi2Status_fmi2Warning => "Warning",
        b::fmi2Status_fmi2Discard => "Discard",
        b::fmi2Status_fmi2Error => "Error",
        b::fmi2Status_fmi2Fatal => "Fatal",
        b::fmi2Status_fmi2Pending => "Pending",
        _ => "an unknown status",
    }
}

/// One FMI 2.0 co-simulation instance.
pub struct Cs2 {
    /// Not unloaded after a fatal error (the library's state is corrupt: unloading it ran
    /// pythonfmu's teardown into glibc's "free(): corrupted unsorted chunks", SIGABRT).
    bind: std::mem::ManuallyDrop<b::Fmi2Binding>,
    c: b::fmi2Component,
    /// The FMU may keep this pointer for the instance's life (FMI 2.0 §2.1.5).
    _callbacks: Box<b::fmi2CallbackFunctions>,
    /// A call returned fmi2Fatal: no call more.
    fatal: bool,
}

impl Cs2 {
    /// fmi2Instantiate for co-simulation, logging on.
    pub fn instantiate(import: &Fmi2Import, name: &str) -> Result<Self, String> {
        let md = import.model_description();
        let id = md
            .co_simulation
            .as_ref()
            .map(|cs| cs.model_identifier.clone())
            .ok_or("no co-simulation interface")?;
        let bind = import
            .binding(&id)
            .map_err(|e| format!("cannot load the library: {e}"))?;
        let callbacks = Box::new(b::fmi2CallbackFunctions {
            logger: Some(uio_fmi2_logger),
            allocateMemory: Some(libc::calloc),
            freeMemory: Some(libc::free),
            stepFinished: None,
            componentEnvironment: std::ptr::null_mut(),
        });
        let cstr = |s: &str| CString::new(s).map_err(|_| format!("'{s}' holds a NUL byte"));
        let (name_c, guid, resources) = (
            cstr(name)?,
            cstr(&md.guid)?,
            cstr(&import.canonical_resource_path_string())?,
        );
        // SAFETY: valid C strings and a callbacks struct that outlives the instance.
        let c = unsafe {
            bind.fmi2Instantiate(
                name_c.as_ptr(),
                b::fmi2Type_fmi2CoSimulation,
                guid.as_ptr(),
                resources.as_ptr(),
                &*callbacks,
                0,
                1,
            )
        };
        if c.is_null() {
            return Err(format!("fmi2Instantiate failed{}", log_capture::take()));
        }
        Ok(Cs2 {
            bind: std::mem::ManuallyDrop::new(bind),
            c,
            _callbacks: callbacks,
            fatal: false,
        })
    }

    fn check(&mut self, call: &str, t: f64, s: b::fmi2Status) -> Result<(), String> {
        if s == b::fmi2Status_fmi2OK || s == b::fmi2Status_fmi2Warning {
            return Ok(());
        }
        if s == b::fmi2Status_fmi2Fatal {
            self.fatal = true;
            FATAL.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        Err(format!(
            "{call} at t = {t} returned {}{}",
            status_name(s),
            log_capture::take()
        ))
    }

    pub fn setup_experiment(&mut self, start: f64) -> Result<(), String> {
        // SAFETY: a live instance (for every call below too).
        let s = unsafe { self.bind.fmi2SetupExperiment(self.c, 0, 0.0, start, 0, 0.0) };
        self.check("fmi2SetupExperiment", start, s)
    }

    pub fn enter_initialization_mode(&mut self) -> Result<(), String> {
        let s = unsafe { self.bind.fmi2EnterInitializationMode(self.c) };
        self.check("fmi2EnterInitializationMode", 0.0, s)
    }

    pub fn exit_initialization_mode(&mut self) -> Result<(), String> {
        let s = unsafe { self.bind.fmi2ExitInitializationMode(self.c) };
        self.check("fmi2ExitInitializationMode", 0.0, s)
    }

    pub fn set_real(&mut self, vrs: &[u32], values: &[f64], t: f64) -> Result<(), String> {
        assert_eq!(vrs.len(), values.len());
        let s = unsafe {
            self.bind
                .fmi2SetReal(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr())
        };
        self.check("fmi2SetReal", t, s)
    }

    pub fn set_integer(&mut self, vrs: &[u32], values: &[i32], t: f64) -> Result<(), String> {
        assert_eq!(vrs.len(), values.len());
        let s = unsafe {
            self.bind
                .fmi2SetInteger(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr())
        };
        self.check("fmi2SetInteger", t, s)
    }

    pub fn set_boolean(&mut self, vrs: &[u32], values: &[i32], t: f64) -> Result<(), String> {
        assert_eq!(vrs.len(), values.len());
        let s = unsafe {
            self.bind
                .fmi2SetBoolean(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr())
        };
        self.check("fmi2SetBoolean", t, s)
    }

    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64], t: f64) -> Result<(), String> {
        assert_eq!(vrs.len(), out.len());
        let s = unsafe {
            self.bind
                .fmi2GetReal(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
        };
        self.check("fmi2GetReal", t, s)
    }

    pub fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        let s = unsafe { self.bind.fmi2DoStep(self.c, t, h, 1) };
        self.check("fmi2DoStep", t, s)
    }
}

impl Drop for Cs2 {
    fn drop(&mut self) {
        if !self.fatal {
            // SAFETY: the instance is live and freed once, then its library unloaded once.
            unsafe {
                self.bind.fmi2FreeInstance(self.c);
                std::mem::ManuallyDrop::drop(&mut self.bind);
            }
        }
    }
}
