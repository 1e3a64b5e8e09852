//! The Embree device: created once, with an error callback that collects messages so they can
//! be checked after building and committing (never per ray).

use crate::Error;
use embree_sys::*;
use std::ffi::{c_char, c_void, CStr, CString};
use std::sync::Mutex;

pub struct Device {
    pub(super) raw: RTCDevice,
    errors: *mut Mutex<Vec<String>>,
    /// Packet width for primary rays: 16 where the CPU traces 16-wide natively, else 8.
    pub packet_width: usize,
}

// Embree devices are thread-safe; the error list is behind a mutex.
unsafe impl Send for Device {}
unsafe impl Sync for Device {}

unsafe extern "C" fn on_error(user: *mut c_void, code: RTCError, msg: *const c_char) {
    let text = if msg.is_null() {
        String::new()
    } else {
        unsafe { CStr::from_ptr(msg) }
            .to_string_lossy()
            .into_owned()
    };
    let list = unsafe { &*(user as *const Mutex<Vec<String>>) };
    if let Ok(mut l) = list.lock() {
        l.push(format!("{code:?}: {text}"));
    }
}

impl Device {
    /// A device; `threads` limits Embree's own build threads (0: all cores).
    pub fn new(threads: usize) -> crate::Result<Device> {
        let config = CString::new(format!("threads={threads},verbose=0")).expect("no NUL");
        let raw = unsafe { rtcNewDevice(config.as_ptr()) };
        if raw.is_null() {
            let code = unsafe { rtcGetDeviceError(std::ptr::null_mut()) };
            return Err(Error::backend(format!(
                "Embree could not create a device ({code:?})"
            )));
        }
        let errors = Box::into_raw(Box::new(Mutex::new(Vec::new())));
        unsafe { rtcSetDeviceErrorFunction(raw, Some(on_error), errors as *mut c_void) };
        let native16 =
            unsafe { rtcGetDeviceProperty(raw, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) } != 0;
        Ok(Device {
            raw,
            errors,
            packet_width: if native16 { 16 } else { 8 },
        })
    }

    /// Fail with the collected messages, if Embree reported any since the last check.
    pub fn check(&self, what: &str) -> crate::Result<()> {
        let mut list = unsafe { &*self.errors }
            .lock()
            .map_err(|_| Error::backend("Embree error list poisoned"))?;
        let code = unsafe { rtcGetDeviceError(self.raw) };
        if code != RTCError::RTC_ERROR_NONE && list.is_empty() {
            list.push(format!("{code:?}"));
        }
        if list.is_empty() {
            return Ok(());
        }
        let msg = list.join("; ");
        list.clear();
        Err(Error::backend(format!("Embree failed while {what}: {msg}")))
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        unsafe {
            rtcSetDeviceErrorFunction(self.raw, None, std::ptr::null_mut());
            rtcReleaseDevice(self.raw);
            drop(Box::from_raw(self.errors));
        }
    }
}
