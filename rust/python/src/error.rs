//! Every error that crosses into Python becomes `penumbra.BakeError`, with `kind`, `object`
//! and `field` attributes so that the add-on can report the culprit without parsing text.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    penumbra._core,
    BakeError,
    PyException,
    "A scene could not be baked: bad input, a bad setting, nothing to bake, or a cancel."
);

/// Local wrapper so that the core's error (a foreign type) can convert into `PyErr`.
#[derive(Debug, Clone)]
pub enum Error {
    Bake(penumbra::BakeError),
    /// The bake thread panicked: a bug in the core, reported rather than taking Python down.
    Internal(String),
}

impl From<penumbra::BakeError> for Error {
    fn from(e: penumbra::BakeError) -> Self {
        Error::Bake(e)
    }
}

impl From<Error> for PyErr {
    fn from(e: Error) -> PyErr {
        let (kind, object, field, message) = match &e {
            Error::Bake(b) => {
                let (kind, object, field) = match b {
                    penumbra::BakeError::Format(_) => ("format", None, None),
                    penumbra::BakeError::Invalid { object, field, .. } => {
                        ("invalid", Some(object.clone()), Some(field.clone()))
                    }
                    penumbra::BakeError::Setting { field, .. } => {
                        ("setting", Some("settings".to_string()), Some(field.clone()))
                    }
                    penumbra::BakeError::Empty(_) => ("empty", None, None),
                    penumbra::BakeError::Cancelled => ("cancelled", None, None),
                };
                (kind, object, field, b.to_string())
            }
            Error::Internal(m) => (
                "internal",
                None,
                None,
                format!("internal error in the bake: {m}"),
            ),
        };
        Python::attach(|py| {
            let err = BakeError::new_err(message);
            let value = err.value(py);
            // Attribute setting on a fresh exception instance cannot fail in practice; if it
            // did, the message still carries everything.
            let _ = value.setattr("kind", kind);
            let _ = value.setattr("object", object);
            let _ = value.setattr("field", field);
            err
        })
    }
}

/// Shorthand for an input error found while reading Python objects.
pub fn invalid(object: &str, field: &str, reason: impl Into<String>) -> Error {
    Error::Bake(penumbra::BakeError::invalid(object, field, reason))
}
