//! The Embree device: created null-checked, with an error callback installed at creation
//! that records what went wrong, so that every build step can return it as an
//! [`EmbreeError`].

use std::cell::RefCell;
use std::ffi::{CStr, CString, c_char, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::ptr;
use std::sync::atomic::{AtomicIsize, Ordering};

use super::error::EmbreeError;
use super::sys;

/// What the memory monitor writes. Boxed, so its address stays fixed while Embree
/// holds a pointer to it.
#[derive(Debug, Default)]
struct DeviceState {
    /// Bytes Embree currently has allocated (memory-monitor callback; build time only).
    bytes: AtomicIsize,
}

thread_local! {
    /// The first error Embree reported on this thread since the last
    /// [`Device::check`] there: code and message. Embree calls the error callback on
    /// the thread of the call that failed and keeps its error codes per thread, so
    /// builds on other threads sharing the device never see this one's errors.
    static LAST_ERROR: RefCell<Option<(u32, String)>> = const { RefCell::new(None) };
}

/// An owned `RTCDevice`.
#[derive(Debug)]
pub(super) struct Device {
    raw: sys::RTCDevice,
    /// Read by the callbacks through the pointer registered with Embree; dropped after the
    /// callbacks are unregistered and the device released (see `Drop`).
    state: Box<DeviceState>,
}

// SAFETY: an `RTCDevice` is a handle to Embree's reference-counted device object; Embree
// documents the device API as thread-safe (errors are even stored per thread). The
// `DeviceState` the callbacks write is synchronised (a `Mutex` and an atomic).
unsafe impl Send for Device {}
// SAFETY: as for `Send`: `&Device` only allows `rtcGetDeviceProperty`,
// `rtcGetDeviceError` and reading the synchronised state (errors are kept per thread).
unsafe impl Sync for Device {}

impl Device {
    /// Create a device with Embree's configuration string (`""` for the defaults, e.g.
    /// `"threads=2"`).
    pub(super) fn new(config: &str) -> Result<Device, EmbreeError> {
        let c_config = CString::new(config).map_err(|_| {
            EmbreeError::emray(
                "rtcNewDevice",
                format!("the device configuration {config:?} contains a NUL byte"),
            )
        })?;
        // SAFETY: `c_config` is a valid NUL-terminated string that outlives the call;
        // Embree copies what it needs.
        let raw = unsafe { sys::rtcNewDevice(c_config.as_ptr()) };
        if raw.is_null() {
            // SAFETY: Embree documents `rtcGetDeviceError(NULL)` as the way to get the
            // error of a failed `rtcNewDevice`.
            let code = unsafe { sys::rtcGetDeviceError(ptr::null_mut()) };
            return Err(EmbreeError::embree(
                format!("rtcNewDevice({config:?})"),
                code.0,
                "",
            ));
        }
        let state = Box::new(DeviceState::default());
        let user_ptr = ptr::from_ref::<DeviceState>(&state)
            .cast_mut()
            .cast::<c_void>();
        // SAFETY: `raw` is a live device. `user_ptr` points to the boxed `DeviceState`,
        // which stays at that address until `Drop` has unregistered both callbacks; the
        // callbacks only take shared references to it and use its synchronised fields.
        unsafe {
            sys::rtcSetDeviceErrorFunction(raw, Some(error_callback), user_ptr);
            sys::rtcSetDeviceMemoryMonitorFunction(raw, Some(memory_callback), user_ptr);
        }
        let device = Device { raw, state };
        device.check(format!("rtcNewDevice({config:?})"))?;
        Ok(device)
    }

    /// The raw handle, for the scene builder.
    pub(super) fn raw(&self) -> sys::RTCDevice {
        self.raw
    }

    /// `Err` if Embree reported an error since the last check: the message the error
    /// callback recorded, else the code `rtcGetDeviceError` returns (which also clears
    /// the calling thread's error code).
    pub(super) fn check(&self, operation: impl Into<String>) -> Result<(), EmbreeError> {
        // SAFETY: `self.raw` is a live device.
        let code = unsafe { sys::rtcGetDeviceError(self.raw) };
        let recorded = LAST_ERROR.take();
        match recorded {
            Some((code, message)) => Err(EmbreeError::embree(operation, code, message)),
            None if code != sys::RTCError::RTC_ERROR_NONE => {
                Err(EmbreeError::embree(operation, code.0, ""))
            }
            None => Ok(()),
        }
    }

    /// `rtcGetDeviceProperty`.
    pub(super) fn property(&self, prop: sys::RTCDeviceProperty) -> isize {
        // SAFETY: `self.raw` is a live device; an unknown property only sets an error code.
        unsafe { sys::rtcGetDeviceProperty(self.raw, prop) }
    }

    /// Bytes Embree has allocated through this device right now.
    pub(super) fn allocated_bytes(&self) -> usize {
        usize::try_from(self.state.bytes.load(Ordering::Relaxed)).unwrap_or(0)
    }

    /// Library version and tasking system, e.g. `Embree 3.13.5 (TBB)`.
    pub(super) fn describe(&self) -> String {
        let v = self.property(sys::RTCDeviceProperty::RTC_DEVICE_PROPERTY_VERSION);
        let tasking =
            match self.property(sys::RTCDeviceProperty::RTC_DEVICE_PROPERTY_TASKING_SYSTEM) {
                0 => "internal tasking",
                1 => "TBB",
                2 => "PPL",
                _ => "unknown tasking",
            };
        format!(
            "Embree {}.{}.{} ({tasking})",
            v / 10000,
            v / 100 % 100,
            v % 100
        )
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: `self.raw` is live until `rtcReleaseDevice`. The callbacks are
        // unregistered first so that nothing can reach `self.state` (freed right after
        // this) even if the device outlives this handle.
        unsafe {
            sys::rtcSetDeviceErrorFunction(self.raw, None, ptr::null_mut());
            sys::rtcSetDeviceMemoryMonitorFunction(self.raw, None, ptr::null_mut());
            sys::rtcReleaseDevice(self.raw);
        }
    }
}

/// Embree's error callback: keep the first error (code and message) on this thread for
/// `Device::check`. Never unwinds into Embree.
unsafe extern "C" fn error_callback(
    _user_ptr: *mut c_void,
    code: sys::RTCError,
    message: *const c_char,
) {
    let message = if message.is_null() {
        String::new()
    } else {
        // SAFETY: Embree passes a NUL-terminated string valid for the call.
        unsafe { CStr::from_ptr(message) }
            .to_string_lossy()
            .into_owned()
    };
    // Nothing here should panic, but a panic must not cross into C.
    let _ = catch_unwind(AssertUnwindSafe(|| {
        LAST_ERROR.with_borrow_mut(|slot| {
            if slot.is_none() {
                *slot = Some((code.0, message));
            }
        })
    }));
}

/// Embree's memory monitor: track the bytes allocated; never refuse an allocation.
unsafe extern "C" fn memory_callback(user_ptr: *mut c_void, bytes: isize, _post: bool) -> bool {
    // SAFETY: `user_ptr` is the `DeviceState` registered in `Device::new`, alive until
    // the callback is unregistered in `Drop`; only a shared reference is formed.
    if let Some(state) = unsafe { user_ptr.cast::<DeviceState>().as_ref() } {
        state.bytes.fetch_add(bytes, Ordering::Relaxed);
    }
    true
}
