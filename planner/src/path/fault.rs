//! What is wrong with a path that cannot be planned: [`PathFault`], carried by
//! [`crate::PlanError::InvalidPath`].

/// What is wrong with a path (carried by [`crate::PlanError::InvalidPath`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PathFault {
    /// A path needs at least two points.
    TooFewPoints {
        /// How many points were given.
        count: usize,
    },
    /// Paths are 2-D or 3-D.
    Dimension {
        /// The dimension given.
        dim: usize,
    },
    /// A coordinate is NaN or infinite.
    NonFinite {
        /// 0-based point index.
        index: usize,
        /// 0-based axis (0 = x, 1 = y, 2 = z).
        axis: usize,
        /// The offending value.
        value: f64,
    },
    /// A 2-D path point has a non-zero z.
    OffPlane {
        /// 0-based point index.
        index: usize,
        /// Its z.
        z: f64,
    },
    /// A point coincides with the one before it (zero-length segment, no direction).
    Coincident {
        /// 0-based index of the second of the two points.
        index: usize,
    },
}

impl std::fmt::Display for PathFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            PathFault::TooFewPoints { count } => {
                write!(f, "a path needs at least 2 points, got {count}")
            }
            PathFault::Dimension { dim } => {
                write!(f, "a path is 2-D or 3-D, got dimension {dim}")
            }
            PathFault::NonFinite { index, axis, value } => write!(
                f,
                "point {index}: coordinate {} must be finite, got {value}",
                ["x", "y", "z"][axis.min(2)]
            ),
            PathFault::OffPlane { index, z } => {
                write!(f, "point {index}: a 2-D path needs z = 0, got z = {z}")
            }
            PathFault::Coincident { index } => write!(
                f,
                "point {index} coincides with point {} (zero-length segment)",
                index.saturating_sub(1)
            ),
        }
    }
}
