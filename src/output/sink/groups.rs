//! Signal groups: how the channels of a [`Series`] are gathered into MCAP topics, rerun
//! entities and plot panels, whatever channels a run records.
//!
//! The rule works on channel names alone, so new channels need no sink code:
//! - a name with a dot is `group.field` (e.g. `x.cmd_p` -> group `x`, field `cmd_p`);
//! - otherwise the text before the first `_` is the group and the rest the field
//!   (`cmd_p_x` -> group `cmd`, field `p_x`; `toolhead_x` -> `toolhead`, `x`;
//!   `motor_angle_y` -> `motor`, `angle_y`), so a signal's axes share one group;
//! - a name without `_` is a field of the group of that name (`error`, the length of the
//!   error vector, joins `error_x` and `error_y` in group `error`).
//!
//! A field's key in a message carries its unit the way CSV headers do: `field_unit`
//! (`p_x_m`, `v_x_m_s`), or just `field` when the unit is empty.
//!
//! Groups keep the order in which their first channel appears; fields keep channel order.

use crate::measure::series::Series;

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

fn split(name: &str) -> (String, String) {
    match name.split_once('.').or_else(|| name.split_once('_')) {
        Some((g, f)) if !g.is_empty() && !f.is_empty() => (g.to_string(), f.to_string()),
        _ => (name.to_string(), name.to_string()),
    }
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
    let mut out: Vec<Group> = Vec::new();
    for (i, (name, unit)) in names.iter().zip(units).enumerate() {
        let (g, f) = split(name);
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
    fn one_axis_run() {
        let got = shape(&[
            "cmd_p_x",
            "cmd_v_x",
            "cmd_a_x",
            "cmd_j_x",
            "toolhead_x",
            "error_x",
            "error",
        ]);
        assert_eq!(
            got,
            vec![
                (
                    "cmd".to_string(),
                    vec![
                        "p_x_m".into(),
                        "v_x_m".into(),
                        "a_x_m".into(),
                        "j_x_m".into()
                    ]
                ),
                ("toolhead".to_string(), vec!["x_m".into()]),
                ("error".to_string(), vec!["x_m".into(), "error_m".into()]),
            ]
        );
    }

    #[test]
    fn axes_share_groups_and_dots_name_them() {
        let got = shape(&[
            "motor_angle_x",
            "motor_angle_y",
            "a.cmd_p",
            "b.cmd_p",
            "_odd",
        ]);
        assert_eq!(
            got[0],
            (
                "motor".to_string(),
                vec!["angle_x_m".to_string(), "angle_y_m".to_string()]
            )
        );
        assert_eq!(got[1], ("a".to_string(), vec!["cmd_p_m".to_string()]));
        assert_eq!(got[2], ("b".to_string(), vec!["cmd_p_m".to_string()]));
        assert_eq!(got[3], ("_odd".to_string(), vec!["_odd_m".to_string()]));
        let unitless = group_names(&["status"], &[""]);
        assert_eq!(unitless[0].fields[0].key, "status");
    }
}
