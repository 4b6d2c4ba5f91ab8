//! Validation-layer plumbing. With `DVR_VALIDATION=1` the Khronos validation layer and
//! synchronization validation are enabled; every warning or error it reports is printed
//! and counted, and the applications exit non-zero when the count is not zero. The log is
//! process-wide because the layer's callback has no other home that outlives a device.

use ash::vk;
use std::ffi::CStr;
use std::sync::Mutex;

static MESSAGES: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// True when `DVR_VALIDATION` asks for validation (`1`, `true`, `on`).
pub fn requested() -> bool {
    matches!(
        std::env::var("DVR_VALIDATION").as_deref(),
        Ok("1") | Ok("true") | Ok("on") | Ok("yes")
    )
}

/// Number of validation warnings/errors reported so far in this process.
pub fn message_count() -> usize {
    MESSAGES.lock().map(|m| m.len()).unwrap_or(0)
}

/// A copy of the messages reported so far.
pub fn messages() -> Vec<String> {
    MESSAGES.lock().map(|m| m.clone()).unwrap_or_default()
}

pub(crate) unsafe extern "system" fn callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    _user: *mut std::ffi::c_void,
) -> vk::Bool32 {
    let text = if data.is_null() || (*data).p_message.is_null() {
        "(no message)".to_string()
    } else {
        CStr::from_ptr((*data).p_message)
            .to_string_lossy()
            .into_owned()
    };
    let level = if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        "error"
    } else {
        "warning"
    };
    eprintln!("[vulkan validation {level}] {text}");
    if let Ok(mut m) = MESSAGES.lock() {
        m.push(format!("{level}: {text}"));
    }
    vk::FALSE
}

pub(crate) fn messenger_info() -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
    vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(
            vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
        )
        .message_type(
            vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION,
        )
        .pfn_user_callback(Some(callback))
}
