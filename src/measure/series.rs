//! `Series`: time-stamped named channels with units, for recording one run in full.
//! Metrics read it (through the same streaming accumulator the sweep uses); sinks write it.

use std::io::Write;

use crate::input::runs_table::record;

/// One named channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// Name, e.g. `toolhead`.
    pub name: String,
    /// Unit, e.g. `m`.
    pub unit: String,
    /// Values, one per time stamp.
    pub data: Vec<f64>,
}

/// Time-stamped channels of equal length.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Time stamps (s).
    pub t_s: Vec<f64>,
    /// Channels, each as long as `t_s`.
    pub channels: Vec<Channel>,
}

impl Series {
    /// An empty series with the given `(name, unit)` channels.
    pub fn new(channels: &[(&str, &str)]) -> Self {
        Self {
            t_s: Vec::new(),
            channels: channels
                .iter()
                .map(|(n, u)| Channel {
                    name: n.to_string(),
                    unit: u.to_string(),
                    data: Vec::new(),
                })
                .collect(),
        }
    }

    /// An empty series with the given `(name, unit)` channels (owned names).
    pub fn with_channels(channels: Vec<(String, String)>) -> Self {
        Self {
            t_s: Vec::new(),
            channels: channels
                .into_iter()
                .map(|(name, unit)| Channel {
                    name,
                    unit,
                    data: Vec::new(),
                })
                .collect(),
        }
    }

    /// Append one row: a time stamp and one value per channel, in channel order.
    pub fn push(&mut self, t_s: f64, values: &[f64]) {
        debug_assert_eq!(values.len(), self.channels.len());
        self.t_s.push(t_s);
        for (c, v) in self.channels.iter_mut().zip(values) {
            c.data.push(*v);
        }
    }

    /// The channel called `name`.
    pub fn channel(&self, name: &str) -> Option<&Channel> {
        self.channels.iter().find(|c| c.name == name)
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// True when there are no rows.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// Write as CSV with a `name_unit` header (numbers in Rust's shortest round-trip form).
    pub fn write_csv(&self, mut w: impl Write) -> std::io::Result<()> {
        let mut cells: Vec<String> = Vec::with_capacity(self.channels.len() + 1);
        cells.push("t_s".into());
        cells.extend(
            self.channels
                .iter()
                .map(|c| format!("{}_{}", c.name, c.unit)),
        );
        w.write_all(record(&cells).as_bytes())?;
        for (i, t) in self.t_s.iter().enumerate() {
            cells.clear();
            cells.push(t.to_string());
            cells.extend(self.channels.iter().map(|c| c.data[i].to_string()));
            w.write_all(record(&cells).as_bytes())?;
        }
        Ok(())
    }
}
