//! Khronos validation through a debug-utils messenger: messages are kept, so
//! a test can fail on an API misuse the driver would silently accept.

use super::error::{vk_err, Result};
use ash::vk;
use std::ffi::{c_void, CStr};
use std::sync::{Arc, Mutex};

pub(crate) const LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// One message from the validation layer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ValidationMessage {
    pub error: bool,
    pub text: String,
}

/// The messages of one context's validation layer; it stays readable after
/// the context is dropped, so leaks reported at device destruction are seen.
#[derive(Clone, Debug, Default)]
pub struct ValidationLog(Arc<Mutex<Vec<ValidationMessage>>>);

impl ValidationLog {
    pub fn messages(&self) -> Vec<ValidationMessage> {
        self.0.lock().unwrap_or_else(|p| p.into_inner()).clone()
    }

    /// The error messages, as text.
    pub fn errors(&self) -> Vec<String> {
        self.messages()
            .into_iter()
            .filter(|m| m.error)
            .map(|m| m.text)
            .collect()
    }
}

pub(crate) struct Validation {
    loader: ash::ext::debug_utils::Instance,
    messenger: vk::DebugUtilsMessengerEXT,
    /// Shared with the callback through its user-data pointer; it lives as
    /// long as the messenger because `Validation` owns both.
    log: Arc<Mutex<Vec<ValidationMessage>>>,
}

impl Validation {
    pub(crate) fn new(entry: &ash::Entry, instance: &ash::Instance) -> Result<Self> {
        let loader = ash::ext::debug_utils::Instance::new(entry, instance);
        let log = Arc::new(Mutex::new(Vec::new()));
        let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                    | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::GENERAL,
            )
            .pfn_user_callback(Some(callback))
            .user_data(Arc::as_ptr(&log) as *mut c_void);
        // SAFETY: the instance has VK_EXT_debug_utils; the user data outlives
        // the messenger (see `log`).
        let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }
            .map_err(vk_err("vkCreateDebugUtilsMessengerEXT"))?;
        Ok(Validation {
            loader,
            messenger,
            log,
        })
    }

    pub(crate) fn log(&self) -> ValidationLog {
        ValidationLog(self.log.clone())
    }

    /// # Safety
    /// Call once, before the instance is destroyed.
    pub(crate) unsafe fn destroy(&self) {
        self.loader
            .destroy_debug_utils_messenger(self.messenger, None);
    }
}

unsafe extern "system" fn callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the layer passes valid callback data; `user` is the log
    // pointer given at creation, still alive.
    let text = unsafe { data.as_ref() }
        .and_then(|d| unsafe { d.message_as_c_str() })
        .map(|m| m.to_string_lossy().into_owned())
        .unwrap_or_default();
    let error = severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR);
    eprintln!(
        "vulkan validation {}: {text}",
        if error { "error" } else { "warning" }
    );
    let log = unsafe { &*(user as *const Mutex<Vec<ValidationMessage>>) };
    log.lock()
        .unwrap_or_else(|p| p.into_inner())
        .push(ValidationMessage { error, text });
    vk::FALSE
}
