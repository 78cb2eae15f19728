//! Runs grouped by their swept values other than `profile`: the rows of the summary's
//! side-by-side tables (every study's section uses the same grouping); and which swept keys
//! are settings, which the workload ([`is_setting`]).

use settle_planner::ProfileKind;

use crate::spec::runs::RunList;

/// Whether swept key `key` is a setting (what a user chooses between: compared) rather
/// than part of the workload (the job the settings are compared on: the move length, the
/// corner angle and legs, the scan's speed and width; grouped by).
pub fn is_setting(key: &str) -> bool {
    const WORKLOAD: [&str; 8] = [
        "move.distance_mm",
        "move.start_mm",
        "corner.angle_deg",
        "corner.leg_in_mm",
        "corner.leg_out_mm",
        "scan.v_scan_mm_s",
        "scan.width_mm",
        "scan.settle_margin_s",
    ];
    !WORKLOAD.contains(&key)
}

/// Runs grouped by their swept values other than `profile` (first-seen order): the rows of
/// the summary's side-by-side tables.
#[derive(Debug)]
pub struct SweptGroups {
    /// The profile kinds, in first-seen order (the tables' column groups).
    pub kinds: Vec<ProfileKind>,
    /// Per swept point: its values joined by ` | `, and the indices of its runs.
    pub groups: Vec<(String, Vec<usize>)>,
    /// The swept parameters other than `profile`, in sweep order.
    pub params: Vec<String>,
}

impl SweptGroups {
    /// Group `runs`.
    pub fn of(runs: &dyn RunList) -> Self {
        let mut kinds: Vec<ProfileKind> = Vec::new();
        let mut groups: Vec<(String, Vec<usize>)> = Vec::new();
        for (i, r) in runs.iter().enumerate() {
            if !kinds.contains(&r.profile) {
                kinds.push(r.profile);
            }
            let key: Vec<String> = r
                .swept
                .iter()
                .filter(|(p, _)| p != "profile")
                .map(|(_, v)| v.to_string())
                .collect();
            let key = key.join(" | ");
            match groups.iter_mut().find(|(k, _)| *k == key) {
                Some((_, v)) => v.push(i),
                None => groups.push((key, vec![i])),
            }
        }
        let params: Vec<String> = runs
            .first()
            .map(|r| {
                r.swept
                    .iter()
                    .filter(|(p, _)| p != "profile")
                    .map(|(p, _)| p.clone())
                    .collect()
            })
            .unwrap_or_default();
        Self {
            kinds,
            groups,
            params,
        }
    }
}
