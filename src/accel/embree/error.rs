//! The Embree backend's error type.

use super::sys;

/// A failure while creating the Embree device or building the scene: what failed and,
/// when Embree reported it, Embree's error code and message.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("Embree: {operation} failed: {detail}")]
pub struct EmbreeError {
    operation: String,
    code: Option<u32>,
    message: String,
    /// Display form of `code` and `message`.
    detail: String,
}

impl EmbreeError {
    /// An error Embree reported (`code` is an `RTCError` value).
    pub(super) fn embree(
        operation: impl Into<String>,
        code: u32,
        message: impl Into<String>,
    ) -> Self {
        let message = message.into();
        let detail = if message.is_empty() {
            format!(
                "{} (error code {code}): {}",
                code_name(code),
                code_meaning(code)
            )
        } else {
            format!("{} (error code {code}): {message}", code_name(code))
        };
        EmbreeError {
            operation: operation.into(),
            code: Some(code),
            message,
            detail,
        }
    }

    /// An error found by emray before calling Embree (bad argument, size limit).
    pub(super) fn emray(operation: impl Into<String>, message: impl Into<String>) -> Self {
        let message = message.into();
        EmbreeError {
            operation: operation.into(),
            code: None,
            detail: message.clone(),
            message,
        }
    }

    /// The operation that failed (an Embree function name, or a step of the build).
    pub fn operation(&self) -> &str {
        &self.operation
    }

    /// Embree's `RTCError` code, or `None` when emray refused the input before calling
    /// Embree.
    pub fn code(&self) -> Option<u32> {
        self.code
    }

    /// Embree's message (possibly empty), or emray's.
    pub fn message(&self) -> &str {
        &self.message
    }
}

/// The `RTCError` constant name.
fn code_name(code: u32) -> &'static str {
    match sys::RTCError(code) {
        sys::RTCError::RTC_ERROR_NONE => "RTC_ERROR_NONE",
        sys::RTCError::RTC_ERROR_UNKNOWN => "RTC_ERROR_UNKNOWN",
        sys::RTCError::RTC_ERROR_INVALID_ARGUMENT => "RTC_ERROR_INVALID_ARGUMENT",
        sys::RTCError::RTC_ERROR_INVALID_OPERATION => "RTC_ERROR_INVALID_OPERATION",
        sys::RTCError::RTC_ERROR_OUT_OF_MEMORY => "RTC_ERROR_OUT_OF_MEMORY",
        sys::RTCError::RTC_ERROR_UNSUPPORTED_CPU => "RTC_ERROR_UNSUPPORTED_CPU",
        sys::RTCError::RTC_ERROR_CANCELLED => "RTC_ERROR_CANCELLED",
        _ => "unknown RTCError",
    }
}

/// What an `RTCError` means, for errors that came without a message.
fn code_meaning(code: u32) -> &'static str {
    match sys::RTCError(code) {
        sys::RTCError::RTC_ERROR_NONE => "no error recorded",
        sys::RTCError::RTC_ERROR_INVALID_ARGUMENT => "an invalid argument was specified",
        sys::RTCError::RTC_ERROR_INVALID_OPERATION => "the operation is not allowed",
        sys::RTCError::RTC_ERROR_OUT_OF_MEMORY => "not enough memory",
        sys::RTCError::RTC_ERROR_UNSUPPORTED_CPU => "the CPU is not supported by Embree",
        sys::RTCError::RTC_ERROR_CANCELLED => "the operation was cancelled",
        _ => "unknown error",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_the_operation_code_and_message() {
        let e = EmbreeError::embree("rtcCommitScene", 4, "");
        let s = e.to_string();
        assert!(s.contains("rtcCommitScene"), "{s}");
        assert!(s.contains("RTC_ERROR_OUT_OF_MEMORY (error code 4)"), "{s}");
        assert!(s.contains("not enough memory"), "{s}");
        let e = EmbreeError::embree("rtcNewDevice", 2, "unknown config option");
        assert!(
            e.to_string()
                .ends_with("RTC_ERROR_INVALID_ARGUMENT (error code 2): unknown config option")
        );
        assert_eq!(e.code(), Some(2));
        assert_eq!(e.message(), "unknown config option");
    }

    #[test]
    fn is_usable_as_a_source_error() {
        fn assert_bounds<T: std::error::Error + Send + Sync + 'static>() {}
        assert_bounds::<EmbreeError>();
    }
}
