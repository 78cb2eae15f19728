//! `--shard slurm` and `--shard kubernetes`: shard K of N taken from a cluster scheduler's
//! environment instead of the command line, so that one job script serves every task.
//!
//! - Slurm (a job array, `sbatch --array=A-B[:S]`): Slurm sets `SLURM_ARRAY_TASK_ID`, and
//!   for the whole array `SLURM_ARRAY_TASK_MIN`, `_MAX`, `_STEP` and `_COUNT` (sbatch(1),
//!   "OUTPUT ENVIRONMENT VARIABLES"). Task `id` is shard `(id - MIN) / STEP + 1` of `COUNT`,
//!   so `--array=1-16`, `--array=0-15` and `--array=0-30:2` all give shards 1..16 of 16.
//!   An array that is not such a range (a list like `--array=1,2,7`) has no shard order and
//!   is refused, and so is a one-task array (`--array=5`, the usual way to rerun one task,
//!   would otherwise run the whole sweep as shard 1 of 1): give `--shard K/N` for those.
//! - Kubernetes (an Indexed Job): the Job controller sets `JOB_COMPLETION_INDEX` (0-based)
//!   in every pod, but not the Job's `completions`; the Job spec gives it to the container
//!   as [`SHARD_COUNT_VAR`]. Index `i` is shard `i + 1` of that count.
//!
//! Outside such a job the variables are missing and the sweep stops with an input error
//! (exit 2) that says what was looked for, before any work.

use crate::error::Error;
use crate::workflows::shard::Shard;

/// The variable a Kubernetes Job spec sets to its `completions` (the number of shards).
pub const SHARD_COUNT_VAR: &str = "SETTLE_SHARD_COUNT";

/// What `--shard` was given: K/N itself, or the scheduler whose environment holds them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShardArg {
    /// `--shard K/N`.
    Given(Shard),
    /// `--shard slurm`: from a Slurm job array's task.
    Slurm,
    /// `--shard kubernetes`: from a Kubernetes Indexed Job's completion index.
    Kubernetes,
}

impl std::str::FromStr for ShardArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "slurm" => Ok(Self::Slurm),
            "kubernetes" => Ok(Self::Kubernetes),
            _ => s.parse().map(Self::Given).map_err(|e: String| {
                format!("{e}; or `slurm` (a Slurm job array's task) or `kubernetes` (an Indexed Job's completion index)")
            }),
        }
    }
}

/// A resolved shard and where it came from (`SLURM_ARRAY_TASK_ID=3 of 1-16`), for the
/// sweep's log.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Resolved {
    /// The shard.
    pub shard: Shard,
    /// Where K and N came from; empty for `--shard K/N`.
    pub source: String,
}

impl ShardArg {
    /// The shard, reading the scheduler's variables through `env` (`std::env::var` in the
    /// binary, a table in tests).
    pub fn resolve(&self, env: &dyn Fn(&str) -> Option<String>) -> Result<Resolved, Error> {
        match self {
            Self::Given(shard) => Ok(Resolved {
                shard: *shard,
                source: String::new(),
            }),
            Self::Slurm => slurm(env),
            Self::Kubernetes => kubernetes(env),
        }
    }
}

fn err(message: String) -> Error {
    Error::input("--shard", message)
}

/// Variable `name` as a whole number, `None` when unset.
fn number(env: &dyn Fn(&str) -> Option<String>, name: &str) -> Result<Option<usize>, Error> {
    env(name)
        .map(|v| {
            v.trim().parse::<usize>().map_err(|_| {
                err(format!(
                    "{name}=`{}` is not a whole number >= 0",
                    crate::error::echo(&v)
                ))
            })
        })
        .transpose()
}

fn slurm(env: &dyn Fn(&str) -> Option<String>) -> Result<Resolved, Error> {
    let Some(id) = number(env, "SLURM_ARRAY_TASK_ID")? else {
        let inside = env("SLURM_JOB_ID").map_or(String::new(), |j| {
            format!(" (this is Slurm job {j}, not a task of a job array)")
        });
        return Err(err(format!(
            "slurm: SLURM_ARRAY_TASK_ID is not set{inside}: run it as a job array task \
(`sbatch --array=1-N JOB_SCRIPT`), or give --shard K/N"
        )));
    };
    let need = |name: &str| -> Result<usize, Error> {
        number(env, name)?.ok_or_else(|| {
            err(format!(
                "slurm: SLURM_ARRAY_TASK_ID is set but {name} is not (Slurm sets it in every task of a job array)"
            ))
        })
    };
    let count = need("SLURM_ARRAY_TASK_COUNT")?;
    let min = need("SLURM_ARRAY_TASK_MIN")?;
    let max = need("SLURM_ARRAY_TASK_MAX")?;
    let step = number(env, "SLURM_ARRAY_TASK_STEP")?.unwrap_or(1);
    let array =
        format!("SLURM_ARRAY_TASK_MIN={min}, _MAX={max}, _STEP={step}, _COUNT={count}, _ID={id}");
    let is_range = step >= 1
        && count >= 1
        && (count - 1)
            .checked_mul(step)
            .and_then(|span| span.checked_add(min))
            == Some(max);
    if !is_range {
        return Err(err(format!(
            "slurm: the job array is not a range A-B[:S] ({array}), so its tasks have no shard order: \
submit it as --array=1-N, or give --shard K/N"
        )));
    }
    if count == 1 {
        return Err(err(format!(
            "slurm: a job array of one task ({array}) is not a sharded sweep: to rerun one shard, give it as --shard K/N"
        )));
    }
    if id < min || id > max || (id - min) % step != 0 {
        return Err(err(format!(
            "slurm: SLURM_ARRAY_TASK_ID={id} is not one of the array's indices ({array})"
        )));
    }
    let shard = Shard {
        k: (id - min) / step + 1,
        n: count,
    };
    Ok(Resolved {
        shard,
        source: format!(
            "Slurm array task SLURM_ARRAY_TASK_ID={id} of {min}-{max}{}",
            if step > 1 {
                format!(":{step}")
            } else {
                String::new()
            }
        ),
    })
}

fn kubernetes(env: &dyn Fn(&str) -> Option<String>) -> Result<Resolved, Error> {
    let Some(index) = number(env, "JOB_COMPLETION_INDEX")? else {
        return Err(err(
            "kubernetes: JOB_COMPLETION_INDEX is not set: run it in a pod of an Indexed Job \
(`completionMode: Indexed`), or give --shard K/N"
                .into(),
        ));
    };
    let Some(count) = number(env, SHARD_COUNT_VAR)? else {
        return Err(err(format!(
            "kubernetes: JOB_COMPLETION_INDEX={index} is set but {SHARD_COUNT_VAR} is not: \
Kubernetes does not give a pod its Job's completion count, so set {SHARD_COUNT_VAR} in the container's env to the Job's `completions`"
        )));
    };
    if count == 0 || index >= count {
        return Err(err(format!(
            "kubernetes: JOB_COMPLETION_INDEX={index} with {SHARD_COUNT_VAR}={count}: \
the index must be below the count (set {SHARD_COUNT_VAR} to the Job's `completions`)"
        )));
    }
    Ok(Resolved {
        shard: Shard {
            k: index + 1,
            n: count,
        },
        source: format!(
            "Kubernetes completion index JOB_COMPLETION_INDEX={index} of {SHARD_COUNT_VAR}={count}"
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(vars: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |name| {
            vars.iter()
                .find(|(k, _)| *k == name)
                .map(|(_, v)| v.to_string())
        }
    }

    fn shard(arg: ShardArg, vars: &[(&str, &str)]) -> Result<Shard, String> {
        arg.resolve(&env(vars))
            .map(|r| r.shard)
            .map_err(|e| e.to_string())
    }

    /// The variables Slurm 22.05 set in task `id` of `sbatch --array=MIN-MAX:STEP`
    /// (recorded from `env` in array tasks on a single-node Slurm).
    fn array(id: usize, min: usize, max: usize, step: usize, count: usize) -> Vec<[String; 2]> {
        [
            ("SLURM_JOB_ID", 100 + id),
            ("SLURM_ARRAY_JOB_ID", 99),
            ("SLURM_ARRAY_TASK_ID", id),
            ("SLURM_ARRAY_TASK_MIN", min),
            ("SLURM_ARRAY_TASK_MAX", max),
            ("SLURM_ARRAY_TASK_STEP", step),
            ("SLURM_ARRAY_TASK_COUNT", count),
        ]
        .map(|(k, v)| [k.to_string(), v.to_string()])
        .to_vec()
    }

    fn slurm_shard(vars: &[[String; 2]]) -> Result<Shard, String> {
        let pairs: Vec<(&str, &str)> = vars.iter().map(|[k, v]| (&k[..], &v[..])).collect();
        shard(ShardArg::Slurm, &pairs)
    }

    #[test]
    fn parses_the_three_forms() {
        assert_eq!("slurm".parse(), Ok(ShardArg::Slurm));
        assert_eq!("kubernetes".parse(), Ok(ShardArg::Kubernetes));
        assert_eq!("3/4".parse(), Ok(ShardArg::Given(Shard { k: 3, n: 4 })));
        for bad in ["Slurm", "k8s", "5/4", ""] {
            let e = bad.parse::<ShardArg>().expect_err(bad);
            assert!(
                e.contains("K/N") && e.contains("slurm") && e.contains("kubernetes"),
                "{e}"
            );
        }
    }

    #[test]
    fn slurm_arrays_from_one_from_zero_and_with_a_step_give_the_same_shards() {
        // --array=1-16: task 1 is shard 1, task 16 shard 16.
        assert_eq!(
            slurm_shard(&array(1, 1, 16, 1, 16)),
            Ok(Shard { k: 1, n: 16 })
        );
        assert_eq!(
            slurm_shard(&array(16, 1, 16, 1, 16)),
            Ok(Shard { k: 16, n: 16 })
        );
        // --array=0-15: task 0 is shard 1.
        assert_eq!(
            slurm_shard(&array(0, 0, 15, 1, 16)),
            Ok(Shard { k: 1, n: 16 })
        );
        assert_eq!(
            slurm_shard(&array(7, 0, 15, 1, 16)),
            Ok(Shard { k: 8, n: 16 })
        );
        // --array=0-6:3 (tasks 0, 3, 6): task 3 is shard 2 of 3.
        assert_eq!(slurm_shard(&array(3, 0, 6, 3, 3)), Ok(Shard { k: 2, n: 3 }));
        // --array=5-8: task 8 is shard 4 of 4.
        assert_eq!(slurm_shard(&array(8, 5, 8, 1, 4)), Ok(Shard { k: 4, n: 4 }));
        // The source is said.
        let pairs = array(3, 1, 16, 1, 16);
        let pairs: Vec<(&str, &str)> = pairs.iter().map(|[k, v]| (&k[..], &v[..])).collect();
        let r = ShardArg::Slurm.resolve(&env(&pairs)).expect("resolves");
        assert_eq!(r.source, "Slurm array task SLURM_ARRAY_TASK_ID=3 of 1-16");
    }

    #[test]
    fn slurm_outside_an_array_or_with_an_array_that_is_not_a_range_is_an_error() {
        let e = shard(ShardArg::Slurm, &[]).expect_err("no Slurm");
        assert!(
            e.contains("SLURM_ARRAY_TASK_ID is not set") && e.contains("--array=1-N"),
            "{e}"
        );
        assert!(e.starts_with("--shard: "), "{e}");
        let e = shard(ShardArg::Slurm, &[("SLURM_JOB_ID", "42")]).expect_err("a plain job");
        assert!(e.contains("Slurm job 42, not a task of a job array"), "{e}");
        // --array=1,2,7: COUNT 3 but MIN..MAX spans 7 indices.
        let e = slurm_shard(&array(7, 1, 7, 1, 3)).expect_err("a list");
        assert!(e.contains("not a range"), "{e}");
        // --array=5, the usual rerun of one task: not shard 1 of 1.
        let e = slurm_shard(&array(5, 5, 5, 1, 1)).expect_err("one task");
        assert!(e.contains("one task") && e.contains("--shard K/N"), "{e}");
        // An index that is not on the array's grid.
        let e = slurm_shard(&array(4, 0, 6, 3, 3)).expect_err("off the grid");
        assert!(e.contains("not one of the array's indices"), "{e}");
        let mut bad = array(2, 1, 4, 1, 4);
        bad[6][1] = "four".into();
        let e = slurm_shard(&bad).expect_err("not a number");
        assert!(
            e.contains("SLURM_ARRAY_TASK_COUNT=`four` is not a whole number"),
            "{e}"
        );
        let e = slurm_shard(&array(2, 1, 4, 1, 4)[..3]).expect_err("partial");
        assert!(e.contains("SLURM_ARRAY_TASK_COUNT is not"), "{e}");
    }

    #[test]
    fn kubernetes_index_is_zero_based_and_the_count_comes_from_the_job_spec() {
        let k8s = |vars: &[(&str, &str)]| shard(ShardArg::Kubernetes, vars);
        assert_eq!(
            k8s(&[("JOB_COMPLETION_INDEX", "0"), (SHARD_COUNT_VAR, "16")]),
            Ok(Shard { k: 1, n: 16 })
        );
        assert_eq!(
            k8s(&[("JOB_COMPLETION_INDEX", "15"), (SHARD_COUNT_VAR, "16")]),
            Ok(Shard { k: 16, n: 16 })
        );
        let e = k8s(&[]).expect_err("outside");
        assert!(
            e.contains("JOB_COMPLETION_INDEX is not set") && e.contains("Indexed"),
            "{e}"
        );
        let e = k8s(&[("JOB_COMPLETION_INDEX", "3")]).expect_err("no count");
        assert!(
            e.contains("SETTLE_SHARD_COUNT is not") && e.contains("completions"),
            "{e}"
        );
        let e = k8s(&[("JOB_COMPLETION_INDEX", "16"), (SHARD_COUNT_VAR, "16")])
            .expect_err("past the count");
        assert!(e.contains("below the count"), "{e}");
        let e =
            k8s(&[("JOB_COMPLETION_INDEX", "-1"), (SHARD_COUNT_VAR, "16")]).expect_err("negative");
        assert!(
            e.contains("JOB_COMPLETION_INDEX=`-1` is not a whole number"),
            "{e}"
        );
    }

    #[test]
    fn a_given_shard_needs_no_environment() {
        let r = ShardArg::Given(Shard { k: 2, n: 3 })
            .resolve(&env(&[]))
            .expect("given");
        assert_eq!((r.shard, r.source.as_str()), (Shard { k: 2, n: 3 }, ""));
    }
}
