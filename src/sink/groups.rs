//! Signal groups: how the channels of a [`Series`] are gathered into MCAP topics, rerun
//! entities and plot panels, whatever channels a run records.
//!
//! The rule works on channel names alone, so new channels need no sink code:
//! - a name with a dot is `group.field` (e.g. `x.cmd_p` -> group `x`, field `cmd_p`);
//! - otherwise the text before the first `_` is the group when at least two channels share
//!   it (`cmd_p`, `cmd_v`, `cmd_a`, `cmd_j` -> group `cmd`, fields `p`, `v`, `a`, `j`);
//! - otherwise the channel is a group of its own, its field named like it (`toolhead`).
//!
//! A field's key in a message carries its unit the way CSV headers do: `field_unit`
//! (`p_m`, `v_m_s`), or just `field` when the unit is empty.
//!
//! Groups keep the order in which their first channel appears; fields keep channel order.

use crate::series::Series;

/// One group of channels.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// Group name (topic `/name`, entity `name/...`).
    pub name: String,
    /// The group's fields.
    pub fields: Vec<Field>,
}

/// One channel as a field of its group.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// Index of the channel in the series.
    pub channel: usize,
    /// Field name without the unit (e.g. `p`).
    pub name: String,
    /// Unit as written in the series (e.g. `m_s`).
    pub unit: String,
    /// Key in messages: `name_unit`, or `name` when the unit is empty.
    pub key: String,
    /// The full channel name (e.g. `cmd_p`).
    pub channel_name: String,
}

fn split(name: &str, shared_prefix: impl Fn(&str) -> bool) -> (String, String) {
    if let Some((g, f)) = name.split_once('.') {
        return (g.to_string(), f.to_string());
    }
    if let Some((g, f)) = name.split_once('_')
        && shared_prefix(g)
    {
        return (g.to_string(), f.to_string());
    }
    (name.to_string(), name.to_string())
}

/// The groups of a series (see the module doc for the rule).
pub fn groups(series: &Series) -> Vec<Group> {
    let names: Vec<&str> = series.channels.iter().map(|c| c.name.as_str()).collect();
    group_names(
        &names,
        &series
            .channels
            .iter()
            .map(|c| c.unit.as_str())
            .collect::<Vec<_>>(),
    )
}

/// The groups of channels given by name and unit (in series order).
pub fn group_names(names: &[&str], units: &[&str]) -> Vec<Group> {
    let prefix_count = |p: &str| {
        names
            .iter()
            .filter(|n| !n.contains('.') && n.split_once('_').is_some_and(|(g, _)| g == p))
            .count()
    };
    let mut out: Vec<Group> = Vec::new();
    for (i, (name, unit)) in names.iter().zip(units).enumerate() {
        let (g, f) = split(name, |p| prefix_count(p) >= 2);
        let key = if unit.is_empty() {
            f.clone()
        } else {
            format!("{f}_{unit}")
        };
        let field = Field {
            channel: i,
            name: f,
            unit: unit.to_string(),
            key,
            channel_name: name.to_string(),
        };
        match out.iter_mut().find(|x| x.name == g) {
            Some(grp) => grp.fields.push(field),
            None => out.push(Group {
                name: g,
                fields: vec![field],
            }),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shape(names: &[&str]) -> Vec<(String, Vec<String>)> {
        let units = vec!["m"; names.len()];
        group_names(names, &units)
            .into_iter()
            .map(|g| (g.name, g.fields.into_iter().map(|f| f.key).collect()))
            .collect()
    }

    #[test]
    fn todays_channels() {
        let got = shape(&["cmd_p", "cmd_v", "cmd_a", "cmd_j", "toolhead", "error"]);
        assert_eq!(
            got,
            vec![
                (
                    "cmd".to_string(),
                    vec!["p_m".into(), "v_m".into(), "a_m".into(), "j_m".into()]
                ),
                ("toolhead".to_string(), vec!["toolhead_m".into()]),
                ("error".to_string(), vec!["error_m".into()]),
            ]
        );
    }

    #[test]
    fn dotted_and_lonely_prefixes() {
        let got = shape(&["x.cmd_p", "y.cmd_p", "motor_angle", "following_error"]);
        assert_eq!(got[0], ("x".to_string(), vec!["cmd_p_m".to_string()]));
        assert_eq!(got[1], ("y".to_string(), vec!["cmd_p_m".to_string()]));
        // A prefix used once is no group: the channel keeps its whole name.
        assert_eq!(got[2].0, "motor_angle");
        assert_eq!(got[3].0, "following_error");
        let unitless = group_names(&["status"], &[""]);
        assert_eq!(unitless[0].fields[0].key, "status");
    }
}
