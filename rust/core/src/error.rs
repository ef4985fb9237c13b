//! Errors a bake can end with. Each names the object and the field, so that a user can find
//! the bad value in their scene without a debugger.

use std::fmt;

/// Why a scene could not be baked.
#[derive(Debug, Clone, PartialEq)]
pub enum BakeError {
    /// The scene JSON could not be parsed, or has the wrong format/version.
    Format(String),
    /// A value in the scene is invalid: `object` names the mesh or light (with its index),
    /// `field` the field, `reason` what is wrong with it.
    Invalid {
        object: String,
        field: String,
        reason: String,
    },
    /// A setting is out of its sane range, or would make the bake too large.
    Setting { field: String, reason: String },
    /// Nothing to bake (no receivers or no lights).
    Empty(String),
    /// The bake was cancelled by the caller.
    Cancelled,
}

impl BakeError {
    pub fn invalid(
        object: impl Into<String>,
        field: impl Into<String>,
        reason: impl Into<String>,
    ) -> Self {
        BakeError::Invalid {
            object: object.into(),
            field: field.into(),
            reason: reason.into(),
        }
    }
    pub fn setting(field: impl Into<String>, reason: impl Into<String>) -> Self {
        BakeError::Setting {
            field: field.into(),
            reason: reason.into(),
        }
    }
}

impl fmt::Display for BakeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BakeError::Format(m) => write!(f, "scene format: {m}"),
            BakeError::Invalid {
                object,
                field,
                reason,
            } => write!(f, "{object}: {field}: {reason}"),
            BakeError::Setting { field, reason } => write!(f, "settings.{field}: {reason}"),
            BakeError::Empty(m) => write!(f, "nothing to bake: {m}"),
            BakeError::Cancelled => write!(f, "bake cancelled"),
        }
    }
}

impl std::error::Error for BakeError {}
