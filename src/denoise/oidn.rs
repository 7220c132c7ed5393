//! The few entry points of OIDN 2's C API (oidn.h) that denoising needs, resolved from a
//! library loaded at run time, wrapped so that handles are released and errors reported
//! with OIDN's own message.

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};

type Handle = *mut c_void;

const DEVICE_TYPE_CPU: c_int = 1;
const FORMAT_FLOAT3: c_int = 3;
const ERROR_NONE: c_int = 0;
pub const QUALITY_FAST: i32 = 4;
pub const QUALITY_BALANCED: i32 = 5;
pub const QUALITY_HIGH: i32 = 6;

#[derive(Debug, thiserror::Error)]
pub enum DenoiseError {
    #[error("Open Image Denoise library not found at {0}")]
    NotFound(PathBuf),
    #[error("cannot load Open Image Denoise from {path}: {message}")]
    Load { path: PathBuf, message: String },
    #[error("Open Image Denoise error ({code}) in {during}: {message}")]
    Oidn {
        code: i32,
        during: String,
        message: String,
    },
    #[error("denoise: {0}")]
    Input(String),
    // Not a #[source]: the message already includes it (anyhow would print it twice).
    #[error("provisioning Open Image Denoise: {0}")]
    Provision(super::provision::ProvisionError),
}

impl From<super::provision::ProvisionError> for DenoiseError {
    fn from(e: super::provision::ProvisionError) -> Self {
        DenoiseError::Provision(e)
    }
}

struct Api {
    new_device: unsafe extern "C" fn(c_int) -> Handle,
    set_device_bool: unsafe extern "C" fn(Handle, *const c_char, bool),
    commit_device: unsafe extern "C" fn(Handle),
    get_device_error: unsafe extern "C" fn(Handle, *mut *const c_char) -> c_int,
    release_device: unsafe extern "C" fn(Handle),
    new_filter: unsafe extern "C" fn(Handle, *const c_char) -> Handle,
    set_shared_filter_image: unsafe extern "C" fn(
        Handle,
        *const c_char,
        *mut c_void,
        c_int,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    set_filter_bool: unsafe extern "C" fn(Handle, *const c_char, bool),
    set_filter_int: unsafe extern "C" fn(Handle, *const c_char, c_int),
    commit_filter: unsafe extern "C" fn(Handle),
    execute_filter: unsafe extern "C" fn(Handle),
    release_filter: unsafe extern "C" fn(Handle),
}

pub struct Lib {
    api: Api,
    // Keeps the code behind `api` mapped.
    _lib: libloading::Library,
}

impl Lib {
    pub fn open(path: &Path) -> Result<Lib, DenoiseError> {
        let err = |m: String| DenoiseError::Load {
            path: path.to_path_buf(),
            message: m,
        };
        // SAFETY: loading a shared library runs its initialisers; OIDN's are benign.
        let lib = unsafe { libloading::Library::new(path) }.map_err(|e| err(e.to_string()))?;
        macro_rules! sym {
            ($name:literal) => {
                // SAFETY: the symbol's type is the one declared in OIDN 2's oidn.h.
                *unsafe { lib.get(concat!($name, "\0").as_bytes()) }
                    .map_err(|e| err(format!("{} (needs Open Image Denoise 2.x): {e}", $name)))?
            };
        }
        let api = Api {
            new_device: sym!("oidnNewDevice"),
            set_device_bool: sym!("oidnSetDeviceBool"),
            commit_device: sym!("oidnCommitDevice"),
            get_device_error: sym!("oidnGetDeviceError"),
            release_device: sym!("oidnReleaseDevice"),
            new_filter: sym!("oidnNewFilter"),
            set_shared_filter_image: sym!("oidnSetSharedFilterImage"),
            set_filter_bool: sym!("oidnSetFilterBool"),
            set_filter_int: sym!("oidnSetFilterInt"),
            commit_filter: sym!("oidnCommitFilter"),
            execute_filter: sym!("oidnExecuteFilter"),
            release_filter: sym!("oidnReleaseFilter"),
        };
        Ok(Lib { api, _lib: lib })
    }

    /// A committed CPU device (thread affinity off, as Cycles sets it).
    pub fn device(&self) -> Result<Device<'_>, DenoiseError> {
        // SAFETY: plain C calls on a handle we own.
        let h = unsafe { (self.api.new_device)(DEVICE_TYPE_CPU) };
        if h.is_null() {
            return Err(DenoiseError::Oidn {
                code: -1,
                during: "oidnNewDevice(CPU)".into(),
                message: "no device created".into(),
            });
        }
        let d = Device { lib: self, h };
        let name = CString::new("setAffinity").unwrap();
        unsafe {
            (self.api.set_device_bool)(h, name.as_ptr(), false);
            (self.api.commit_device)(h);
        }
        d.check("committing the CPU device")?;
        Ok(d)
    }
}

pub struct Device<'a> {
    lib: &'a Lib,
    h: Handle,
}

impl Drop for Device<'_> {
    fn drop(&mut self) {
        unsafe { (self.lib.api.release_device)(self.h) }
    }
}

impl<'a> Device<'a> {
    /// OIDN's pending error, if any (reading it clears it).
    fn check(&self, during: &str) -> Result<(), DenoiseError> {
        let mut msg: *const c_char = std::ptr::null();
        let code = unsafe { (self.lib.api.get_device_error)(self.h, &mut msg) };
        if code == ERROR_NONE {
            return Ok(());
        }
        let message = if msg.is_null() {
            String::new()
        } else {
            unsafe { CStr::from_ptr(msg) }
                .to_string_lossy()
                .into_owned()
        };
        Err(DenoiseError::Oidn {
            code,
            during: during.into(),
            message,
        })
    }

    pub fn filter(&self, kind: &str) -> Result<Filter<'_, 'a>, DenoiseError> {
        let k = CString::new(kind).unwrap();
        let h = unsafe { (self.lib.api.new_filter)(self.h, k.as_ptr()) };
        self.check(&format!("creating filter {kind}"))?;
        if h.is_null() {
            return Err(DenoiseError::Oidn {
                code: -1,
                during: format!("creating filter {kind}"),
                message: "no filter created".into(),
            });
        }
        Ok(Filter { dev: self, h })
    }
}

pub struct Filter<'d, 'a> {
    dev: &'d Device<'a>,
    h: Handle,
}

impl Drop for Filter<'_, '_> {
    fn drop(&mut self) {
        unsafe { (self.dev.lib.api.release_filter)(self.h) }
    }
}

impl Filter<'_, '_> {
    /// Shares a packed float3 buffer of width*height pixels under `name` (the caller keeps
    /// it alive and unmoved until `run` returns).
    pub fn image(
        &self,
        name: &str,
        ptr: *mut c_void,
        width: u32,
        height: u32,
    ) -> Result<(), DenoiseError> {
        let n = CString::new(name).unwrap();
        unsafe {
            (self.dev.lib.api.set_shared_filter_image)(
                self.h,
                n.as_ptr(),
                ptr,
                FORMAT_FLOAT3,
                width as usize,
                height as usize,
                0,
                0,
                0,
            )
        };
        self.dev.check(&format!("setting image {name}"))
    }

    pub fn set_bool(&self, name: &str, v: bool) {
        let n = CString::new(name).unwrap();
        unsafe { (self.dev.lib.api.set_filter_bool)(self.h, n.as_ptr(), v) }
    }

    pub fn set_int(&self, name: &str, v: i32) {
        let n = CString::new(name).unwrap();
        unsafe { (self.dev.lib.api.set_filter_int)(self.h, n.as_ptr(), v) }
    }

    pub fn run(&self) -> Result<(), DenoiseError> {
        unsafe { (self.dev.lib.api.commit_filter)(self.h) };
        self.dev.check("committing the filter")?;
        unsafe { (self.dev.lib.api.execute_filter)(self.h) };
        self.dev.check("executing the filter")
    }
}
