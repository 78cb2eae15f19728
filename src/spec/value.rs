//! The value of a swept parameter.

use settle_planner::ProfileKind;

/// A value of a swept parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A number (in the parameter's unit).
    Number(f64),
    /// A profile kind.
    Study(ProfileKind),
    /// A name (a corner strategy, `machine.preset`).
    Text(String),
}

impl Value {
    /// The number, if this is one.
    pub fn number(&self) -> Option<f64> {
        match self {
            Value::Number(x) => Some(*x),
            Value::Study(_) | Value::Text(_) => None,
        }
    }
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Number(x) => write!(f, "{x}"),
            Value::Study(k) => write!(f, "{k}"),
            Value::Text(t) => f.write_str(t),
        }
    }
}
