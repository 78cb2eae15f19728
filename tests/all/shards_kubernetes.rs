//! The Kubernetes recipe of docs/guide/shards.md: its two manifests (the Indexed Job that
//! sweeps, the Job that merges) parse as YAML, hold what an Indexed Job needs, and their
//! commands, run as the pods would run them (each completion index with the Job's
//! environment, in one folder standing for the shared volume), give the unsharded sweep's
//! outputs byte for byte, also when runs lose steps (every pod must exit 0 for the Job to
//! complete).

use std::path::{Path, PathBuf};
use std::process::Command;

use yaml_rust2::{Yaml, YamlLoader};

use crate::support::root;

/// The ```yaml blocks of the page, parsed (one document each).
fn manifests() -> Vec<Yaml> {
    let page = std::fs::read_to_string(root().join("docs/guide/shards.md")).expect("page");
    let mut blocks = Vec::new();
    let mut lines = page.lines();
    while let Some(line) = lines.next() {
        if line.trim() == "```yaml" {
            let body: Vec<&str> = lines.by_ref().take_while(|l| l.trim() != "```").collect();
            blocks.push(body.join("\n"));
        }
    }
    blocks
        .iter()
        .map(|b| {
            let mut docs = YamlLoader::load_from_str(b)
                .unwrap_or_else(|e| panic!("the page's YAML does not parse: {e}\n{b}"));
            assert_eq!(docs.len(), 1, "one manifest per block:\n{b}");
            docs.remove(0)
        })
        .collect()
}

fn text<'a>(y: &'a Yaml, what: &str) -> &'a str {
    y.as_str()
        .unwrap_or_else(|| panic!("{what} is not a string: {y:?}"))
}

/// The Job's only container.
fn container(job: &Yaml) -> &Yaml {
    let containers = job["spec"]["template"]["spec"]["containers"]
        .as_vec()
        .expect("containers");
    assert_eq!(containers.len(), 1);
    &containers[0]
}

/// The container's command as argv.
fn argv(job: &Yaml) -> Vec<String> {
    container(job)["command"]
        .as_vec()
        .expect("an exec-form command")
        .iter()
        .map(|a| text(a, "a command word").to_string())
        .collect()
}

/// The container's environment as (name, value).
fn env(job: &Yaml) -> Vec<(String, String)> {
    container(job)["env"].as_vec().map_or(Vec::new(), |vars| {
        vars.iter()
            .map(|v| {
                (
                    text(&v["name"], "env name").to_string(),
                    text(&v["value"], "env value").to_string(),
                )
            })
            .collect()
    })
}

/// Where the container runs (the shared volume's mount point): checked against its mount.
fn working_dir(job: &Yaml) -> String {
    let c = container(job);
    let dir = text(&c["workingDir"], "workingDir").to_string();
    let mounts = c["volumeMounts"].as_vec().expect("volumeMounts");
    assert!(
        mounts
            .iter()
            .any(|m| m["mountPath"].as_str() == Some(dir.as_str())),
        "the working folder {dir} is the shared volume"
    );
    dir
}

/// A settle command line of a container, run in `volume` with `env`: `settle` is the
/// binary under test, and `sh` finds it on PATH.
fn run(argv: &[String], volume: &Path, env: &[(String, String)]) -> std::process::Output {
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_settle"));
    let mut cmd = if argv[0] == "settle" {
        Command::new(&bin)
    } else {
        Command::new(&argv[0])
    };
    let path = std::env::join_paths(
        std::iter::once(bin.parent().expect("bin dir").to_path_buf()).chain(std::env::split_paths(
            &std::env::var_os("PATH").unwrap_or_default(),
        )),
    )
    .expect("PATH");
    cmd.args(&argv[1..])
        .current_dir(volume)
        .env("PATH", path)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .envs(env.iter().map(|(k, v)| (k, v)));
    cmd.output().expect("runs")
}

/// Every file under `dir`, relative, sorted, leaving out the shard folders.
fn files(dir: &Path) -> Vec<PathBuf> {
    let shard = |p: &PathBuf| {
        p.components()
            .next()
            .is_some_and(|c| c.as_os_str().to_string_lossy().starts_with("shard-"))
    };
    crate::support::files_under(dir)
        .into_iter()
        .filter(|p| !shard(p))
        .collect()
}

#[test]
fn the_indexed_job_and_the_merge_job_run_as_documented() {
    let jobs = manifests();
    assert_eq!(jobs.len(), 2, "the sweep's Indexed Job and the merge Job");
    let (sweep, merge) = (&jobs[0], &jobs[1]);
    for job in &jobs {
        assert_eq!(text(&job["apiVersion"], "apiVersion"), "batch/v1");
        assert_eq!(text(&job["kind"], "kind"), "Job");
        assert_eq!(
            text(
                &job["spec"]["template"]["spec"]["restartPolicy"],
                "restartPolicy"
            ),
            "Never"
        );
        assert_eq!(
            job["spec"]["template"]["spec"]["volumes"],
            sweep["spec"]["template"]["spec"]["volumes"],
            "both Jobs mount the same volume"
        );
    }
    let spec = &sweep["spec"];
    assert_eq!(text(&spec["completionMode"], "completionMode"), "Indexed");
    let completions = spec["completions"].as_i64().expect("completions");
    let env = env(sweep);
    assert!(
        env.contains(&("SETTLE_SHARD_COUNT".into(), completions.to_string())),
        "SETTLE_SHARD_COUNT is the Job's completions ({completions}): {env:?}"
    );
    // Bad input (settle's exit code 2) fails the Job instead of being retried.
    let rule = &spec["podFailurePolicy"]["rules"][0];
    assert_eq!(text(&rule["action"], "action"), "FailJob");
    assert_eq!(
        text(&rule["onExitCodes"]["containerName"], "containerName"),
        text(&container(sweep)["name"], "container name")
    );
    assert_eq!(
        rule["onExitCodes"]["values"].as_vec(),
        Some(&vec![Yaml::Integer(2)])
    );
    let sweep_argv = argv(sweep);
    assert_eq!(sweep_argv[..2], ["settle", "sweep"]);
    assert!(
        sweep_argv
            .windows(2)
            .any(|w| w == ["--shard", "kubernetes"]),
        "{sweep_argv:?}"
    );
    let merge_argv = argv(merge);
    assert_eq!(working_dir(sweep), working_dir(merge));

    // The volume: the scenario the page names, a small sweep of 16 runs, then one whose
    // runs lose steps in 3 of its shards.
    for scenario in ["tests/shards/big.toml", "tests/shards/big_lost_steps.toml"] {
        let volume = tempfile::tempdir().expect("tempdir");
        let v = volume.path();
        let name = sweep_argv[2].as_str();
        std::fs::create_dir_all(v.join(name).parent().expect("scenario folder")).expect("mkdir");
        std::fs::copy(root().join(scenario), v.join(name)).expect("copy");
        for index in 0..completions {
            let mut pod_env = env.clone();
            pod_env.push(("JOB_COMPLETION_INDEX".into(), index.to_string()));
            let o = run(&sweep_argv, v, &pod_env);
            assert_eq!(
                o.status.code(),
                Some(0),
                "{scenario}: the pod of index {index} must succeed: {}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
        let o = run(&merge_argv, v, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "{scenario}: merge: {err}");
        assert_eq!(
            err.contains("lost_steps"),
            scenario.contains("lost_steps"),
            "{err}"
        );
        let whole = v.join("whole");
        let o = run(
            &["settle", "sweep", name, "--out", "whole"].map(String::from),
            v,
            &[],
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let merged = v.join("results/big");
        let want = files(&whole);
        assert!(want.iter().any(|p| p.ends_with("report.html")), "{want:?}");
        assert_eq!(files(&merged), want, "{scenario}: the same files");
        for f in &want {
            assert!(
                std::fs::read(whole.join(f)).expect("read")
                    == std::fs::read(merged.join(f)).expect("read"),
                "{scenario}: {} differs between the merge and the unsharded sweep",
                f.display()
            );
        }
    }
}
