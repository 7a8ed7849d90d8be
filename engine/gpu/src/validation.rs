//! Collects validation-layer messages so commands can fail on any error or
//! warning and tests can assert on exactly what the layer said.

use ash::vk;
use std::ffi::{c_void, CStr};
use std::sync::{Arc, Mutex, MutexGuard};

/// How serious a validation message is, as counted by weft.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Severity {
    /// The application broke a rule (including synchronization hazards).
    Error,
    /// Likely a bug, not strictly invalid; fails tests like an error.
    Warning,
    /// A performance hint; counted separately, never fails a run.
    Performance,
}

/// One message from the validation layer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ValidationMessage {
    /// Error, warning or performance warning.
    pub severity: Severity,
    /// The VUID or message id name, e.g. `SYNC-HAZARD-WRITE-AFTER-READ`.
    pub id: String,
    /// The full message text.
    pub text: String,
}

impl std::fmt::Display for ValidationMessage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kind = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Performance => "performance warning",
        };
        write!(f, "validation {kind} {}: {}", self.id, self.text)
    }
}

/// Counts of messages by severity.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct ValidationCounts {
    /// Errors, including synchronization hazards.
    pub errors: usize,
    /// Warnings other than performance warnings.
    pub warnings: usize,
    /// Performance warnings, reported separately.
    pub performance: usize,
}

impl ValidationCounts {
    /// True when nothing that should fail a run was reported.
    pub fn is_clean(&self) -> bool {
        self.errors == 0 && self.warnings == 0
    }
}

impl std::fmt::Display for ValidationCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let plural = |n: usize| if n == 1 { "" } else { "s" };
        write!(
            f,
            "{} error{}, {} warning{}, {} performance warning{}",
            self.errors,
            plural(self.errors),
            self.warnings,
            plural(self.warnings),
            self.performance,
            plural(self.performance)
        )
    }
}

/// Thread-safe store of every message the layer reported, shared with the
/// debug-utils callback; it outlives the `Gpu` so destruction-time leak
/// reports can still be read.
#[derive(Debug, Default)]
pub struct ValidationLog {
    messages: Mutex<Vec<ValidationMessage>>,
}

impl ValidationLog {
    /// A new, empty log behind an `Arc` (the callback holds a raw pointer to it).
    pub fn new() -> Arc<Self> {
        Arc::new(Self::default())
    }

    fn lock(&self) -> MutexGuard<'_, Vec<ValidationMessage>> {
        self.messages
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Records a message.
    pub fn push(&self, message: ValidationMessage) {
        self.lock().push(message);
    }

    /// A copy of every message so far.
    pub fn messages(&self) -> Vec<ValidationMessage> {
        self.lock().clone()
    }

    /// Messages of one severity.
    pub fn of(&self, severity: Severity) -> Vec<ValidationMessage> {
        self.lock()
            .iter()
            .filter(|m| m.severity == severity)
            .cloned()
            .collect()
    }

    /// Counts by severity.
    pub fn counts(&self) -> ValidationCounts {
        let mut counts = ValidationCounts::default();
        for m in self.lock().iter() {
            match m.severity {
                Severity::Error => counts.errors += 1,
                Severity::Warning => counts.warnings += 1,
                Severity::Performance => counts.performance += 1,
            }
        }
        counts
    }

    /// Removes and returns every message so far.
    pub fn take(&self) -> Vec<ValidationMessage> {
        std::mem::take(&mut *self.lock())
    }
}

/// Maps the layer's severity and type bits onto weft's three classes;
/// `None` for informational chatter that is not counted.
fn classify(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    types: vk::DebugUtilsMessageTypeFlagsEXT,
) -> Option<Severity> {
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        Some(Severity::Error)
    } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
        if types.contains(vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE) {
            Some(Severity::Performance)
        } else {
            Some(Severity::Warning)
        }
    } else {
        None
    }
}

/// The debug-utils callback; `user_data` points at the `ValidationLog`.
///
/// # Safety
/// Called by the Vulkan loader with valid pointers; `user_data` must be the
/// pointer of a `ValidationLog` that outlives the instance.
pub(crate) unsafe extern "system" fn callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut c_void,
) -> vk::Bool32 {
    let Some(class) = classify(severity, types) else {
        return vk::FALSE;
    };
    if data.is_null() || user_data.is_null() {
        return vk::FALSE;
    }
    let data = &*data;
    let text = |s: Option<&CStr>| {
        s.map(|c| c.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let message = ValidationMessage {
        severity: class,
        id: text(data.message_id_name_as_c_str()),
        text: text(data.message_as_c_str()),
    };
    let log = &*(user_data as *const ValidationLog);
    log.push(message);
    vk::FALSE
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classifies_performance_warnings_separately() {
        use vk::DebugUtilsMessageSeverityFlagsEXT as S;
        use vk::DebugUtilsMessageTypeFlagsEXT as T;
        assert_eq!(classify(S::ERROR, T::VALIDATION), Some(Severity::Error));
        assert_eq!(classify(S::WARNING, T::VALIDATION), Some(Severity::Warning));
        assert_eq!(
            classify(S::WARNING, T::PERFORMANCE),
            Some(Severity::Performance)
        );
        assert_eq!(classify(S::INFO, T::GENERAL), None);
    }

    #[test]
    fn counts_by_severity() {
        let log = ValidationLog::new();
        for severity in [
            Severity::Error,
            Severity::Performance,
            Severity::Performance,
        ] {
            log.push(ValidationMessage {
                severity,
                id: "id".into(),
                text: "t".into(),
            });
        }
        let counts = log.counts();
        assert_eq!(
            counts,
            ValidationCounts {
                errors: 1,
                warnings: 0,
                performance: 2
            }
        );
        assert!(!counts.is_clean());
        assert_eq!(
            counts.to_string(),
            "1 error, 0 warnings, 2 performance warnings"
        );
        assert_eq!(
            log.messages()[1].to_string(),
            "validation performance warning id: t"
        );
        assert_eq!(log.take().len(), 3);
        assert!(log.counts().is_clean());
    }
}
