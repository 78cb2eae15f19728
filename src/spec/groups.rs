//! Runs grouped by their swept values other than `profile`: the rows of the summary's
//! side-by-side tables (every study's section uses the same grouping).

use settle_planner::ProfileKind;

use crate::spec::runs::RunList;

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
