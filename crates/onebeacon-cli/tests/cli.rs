//! End-to-end tests of the `onebeacon` binary: outputs, determinism, bad input.

use crate::common::{bin, run, scratch, text};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const SHORT: &str = r#"
name = "short"
description = "two minutes of the garin2024 mission"
[mission]
duration_s = 120.0
[sweep]
t_com_s = [3.0, 9.0]
"#;

fn short_scenario(dir: &Path) -> String {
    let p = dir.join("short.toml");
    std::fs::write(&p, SHORT).unwrap();
    p.to_string_lossy().into_owned()
}

#[test]
fn scenarios_lists_and_shows_builtins() {
    let out = run(&["scenarios"]);
    assert!(out.status.success());
    assert!(text(&out.stdout).starts_with("garin2024 "));
    let out = run(&["scenarios", "--show", "garin2024"]);
    assert!(out.status.success());
    // what --show prints is a scenario file that runs
    let dir = scratch("show");
    let p = dir.join("copy.toml");
    std::fs::write(&p, text(&out.stdout).replace("# duration_s = 1567", "duration_s = 30")).unwrap();
    let out = run(&["mc", p.to_str().unwrap(), "--runs", "2", "--json"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
}

#[test]
fn run_writes_trajectory_summary_and_plots() {
    let dir = scratch("run");
    let scenario = short_scenario(&dir);
    let out_dir = dir.join("out");
    let out = run(&["run", &scenario, "--seed", "4", "--out", out_dir.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(stdout.contains("range+doppler") && stdout.contains("trajectory.csv"), "{stdout}");

    let csv = std::fs::read_to_string(out_dir.join("trajectory.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for col in [
        "t_s",
        "truth_north_m",
        "truth_east_m",
        "range+doppler_north_m",
        "range+doppler_error_m",
        "rosb_error_m",
        "rosb_nees",
    ] {
        assert!(header.contains(&col), "missing column {col}");
    }
    assert_eq!(lines.count(), 481); // 120 s at 0.25 s, plus t = 0

    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["scenario"], "short");
    assert_eq!(summary["seed"], 4);
    let err = summary["estimators"][0]["mean_error_m"].as_f64().unwrap();
    assert!(err > 0.0 && err < 20.0, "{err}");

    for png in ["top_view.png", "error.png"] {
        let bytes = std::fs::read(out_dir.join(png)).unwrap();
        assert!(bytes.starts_with(b"\x89PNG") && bytes.len() > 10_000, "{png}");
    }
    // and each as an SVG beside it
    for svg in ["top_view.svg", "error.svg"] {
        let text = std::fs::read_to_string(out_dir.join(svg)).unwrap();
        assert!(text.contains("<svg") && text.contains("<polyline") && text.trim_end().ends_with("</svg>"), "{svg}");
    }
    // no staging directory left behind
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(leftovers.is_empty());
}

#[test]
fn mc_json_has_the_contract_fields_and_ignores_thread_count() {
    let dir = scratch("mc");
    let scenario = short_scenario(&dir);
    let cells = |threads: &str| {
        let out = run(&["mc", &scenario, "--runs", "6", "--seed", "9", "--threads", threads, "--json"]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let v: serde_json::Value = serde_json::from_str(&text(&out.stdout)).unwrap();
        assert_eq!(v["scenario"], "short");
        assert_eq!(v["runs"], 6);
        assert_eq!(v["seed"], 9);
        assert!(v["wall_s"].as_f64().unwrap() > 0.0);
        v["cells"].clone()
    };
    let one = cells("1");
    let cells_arr = one.as_array().unwrap();
    assert_eq!(cells_arr.len(), 4); // 2 T_com x 2 estimators
    for c in cells_arr {
        for key in [
            "sweep",
            "estimator",
            "mean_error_m",
            "error_variance_m2",
            "rmse_m",
            "outliers",
            "etd_max_pct",
            "etd_mean_pct",
            "nees_mean",
            "nees_band",
        ] {
            assert!(!c[key].is_null(), "missing {key} in {c}");
        }
        assert!(c["sweep"]["t_com_s"].as_f64().is_some());
    }
    assert_eq!(one, cells("2"));
}

#[test]
fn mc_out_writes_json_and_plot() {
    let dir = scratch("mcout");
    let scenario = short_scenario(&dir);
    let out_dir = dir.join("mc");
    let out = run(&["mc", &scenario, "--runs", "3", "--out", out_dir.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("Mean positioning error"));
    assert!(std::fs::read(out_dir.join("mc_error.png")).unwrap().starts_with(b"\x89PNG"));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("mc.json")).unwrap()).unwrap();
    assert_eq!(v["cells"].as_array().unwrap().len(), 4);
}

#[test]
fn sharded_mc_merges_into_the_unsharded_cells() {
    let dir = scratch("shards");
    let scenario = short_scenario(&dir);
    let json = |out: Output| -> serde_json::Value {
        assert!(out.status.success(), "{}", text(&out.stderr));
        serde_json::from_str(&text(&out.stdout)).unwrap()
    };
    let whole = json(run(&["mc", &scenario, "--runs", "5", "--seed", "4", "--json"]));
    let parts = dir.join("parts");
    for i in 0..3 {
        let out = run(&[
            "mc",
            &scenario,
            "--runs",
            "5",
            "--seed",
            "4",
            "--shard",
            &format!("{i}/3"),
            "--out",
            parts.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", text(&out.stderr));
    }
    let merged = json(run(&["mc", "merge", parts.to_str().unwrap(), "--json"]));
    assert_eq!(merged["cells"], whole["cells"]);
    assert_eq!(merged["scenario"], "short");
    // the table, and a shard missing: one line, exit 2
    let table = run(&["mc", "merge", parts.to_str().unwrap()]);
    assert!(text(&table.stdout).contains("Mean positioning error"), "{}", text(&table.stdout));
    let one = parts.join("partial-1-of-3.json");
    let out = run(&["mc", "merge", one.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("missing shard(s) 0, 2 of 3"), "{err}");
    // the merge's --out over its own partials: refused, the partials kept (cfb7f93
    // replaced the directory and lost them)
    let out = run(&["mc", "merge", parts.to_str().unwrap(), "--out", parts.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("an input of this command"), "{}", text(&out.stderr));
    assert!(one.exists());
}

/// Eight shards of one campaign finishing at once on one machine: each partial is
/// listed in the directory's marker (at cfb7f93 some updates were lost, and `--out` over
/// that directory was then refused).
#[test]
fn concurrent_shards_each_list_their_partial() {
    let dir = scratch("shards-at-once");
    let scenario = short_scenario(&dir);
    let parts = dir.join("parts");
    let children: Vec<_> = (0..8)
        .map(|i| {
            let shard = format!("{i}/8");
            let args = ["mc", &scenario, "--runs", "8", "--shard", &shard, "--out", parts.to_str().unwrap()];
            bin().args(args).stdout(std::process::Stdio::null()).spawn().unwrap()
        })
        .collect();
    for mut c in children {
        assert!(c.wait().unwrap().success());
    }
    let marker = std::fs::read_to_string(parts.join(".onebeacon-output")).unwrap();
    let listed = marker.lines().filter(|l| l.starts_with("partial-")).count();
    assert_eq!(listed, 8, "{marker}");
}

#[test]
fn slurm_script_has_the_array_and_the_merge_after_it() {
    let dir = scratch("slurm");
    let scenario = short_scenario(&dir);
    let campaign = dir.join("campaign");
    let out = run(&[
        "mc",
        &scenario,
        "--runs",
        "5",
        "--slurm",
        "4",
        "--partition",
        "long",
        "--cpus-per-task",
        "2",
        "--out",
        campaign.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let script = std::fs::read_to_string(campaign.join("campaign.sh")).unwrap();
    for needle in [
        "--array=0-3",
        "--dependency=afterok:",
        "--partition='long'",
        "--cpus-per-task=2",
        "--shard \"${SLURM_ARRAY_TASK_ID}/4\"",
        "mc merge",
    ] {
        assert!(script.contains(needle), "{needle} not in\n{script}");
    }
    // the campaign's scenario is the canonical TOML of the one named
    let copy = std::fs::read_to_string(campaign.join("scenario.toml")).unwrap();
    assert!(copy.contains("name = \"short\""), "{copy}");
    // bash can read it
    let syntax = Command::new("bash").arg("-n").arg(campaign.join("campaign.sh")).output().unwrap();
    assert!(syntax.status.success(), "{}", text(&syntax.stderr));
    // more shards than (cell, run) pairs: refused
    let out = run(&["mc", &scenario, "--runs", "2", "--slurm", "5"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("at most that many shards"), "{}", text(&out.stderr));
}

/// A stand-in `sbatch`: saves the job script it reads and runs it at once (each array
/// task in turn, `SLURM_ARRAY_TASK_ID` set), printing a job id.
const STUB_SBATCH: &str = r#"#!/usr/bin/env bash
set -euo pipefail
array=""
for a in "$@"; do case "$a" in --array=*) array=${a#--array=0-} ;; esac; done
n=$(ls "$STUB_JOBS" | wc -l)
script="$STUB_JOBS/job-$n.sh"
cat > "$script"
if [ -n "$array" ]; then
  for i in $(seq 0 "$array"); do SLURM_ARRAY_TASK_ID=$i bash "$script" >> "$STUB_JOBS/log" 2>&1; done
else
  bash "$script" >> "$STUB_JOBS/log" 2>&1
fi
echo "$((100 + n))"
"#;

/// Paths with `$(...)`, backticks, `$VAR`, quotes, spaces and newlines in --out, in the
/// scenario's path and in OUT reach the jobs as the paths they are: nothing in them
/// runs, the shards land where they were sent, and the merge equals the unsharded mc.
#[cfg(unix)]
#[test]
fn slurm_jobs_never_run_their_paths() {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch("slurm-quoting");
    let hostile = "x $(touch PWNED) `touch PWNED2` $HOME \"dq\" 'sq' ;touch PWNED3\nline";
    let scenario_dir = dir.join(format!("s {hostile}"));
    std::fs::create_dir_all(&scenario_dir).unwrap();
    let scenario = short_scenario(&scenario_dir);
    let stub = dir.join("stub");
    let jobs = dir.join("jobs");
    std::fs::create_dir_all(&stub).unwrap();
    std::fs::create_dir_all(&jobs).unwrap();
    std::fs::write(stub.join("sbatch"), STUB_SBATCH).unwrap();
    std::fs::set_permissions(stub.join("sbatch"), std::fs::Permissions::from_mode(0o755)).unwrap();
    let whole = run(&["mc", &scenario, "--runs", "3", "--json"]);
    assert!(whole.status.success(), "{}", text(&whole.stderr));
    let whole: serde_json::Value = serde_json::from_str(&text(&whole.stdout)).unwrap();
    let path = format!("{}:{}", stub.display(), std::env::var("PATH").unwrap_or_default());
    // once with --out, once with OUT overriding it at submission
    for (i, env_out) in [(0, None), (1, Some(dir.join(format!("env {hostile}"))))] {
        let campaign = dir.join(format!("c{i} {hostile}"));
        let out = run(&["mc", &scenario, "--runs", "3", "--slurm", "3", "--out", campaign.to_str().unwrap()]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let mut submit = Command::new("bash");
        submit.arg(campaign.join("campaign.sh")).current_dir(&dir).env("PATH", &path).env("STUB_JOBS", &jobs);
        if let Some(o) = &env_out {
            submit.env("OUT", o);
        }
        let o = submit.output().unwrap();
        let log = std::fs::read_to_string(jobs.join("log")).unwrap_or_default();
        assert!(o.status.success(), "{}{}", text(&o.stderr), log);
        let target = env_out.unwrap_or(campaign);
        for shard in 0..3 {
            assert!(target.join(format!("partials/partial-{shard}-of-3.json")).is_file(), "{log}");
        }
        let merged: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(target.join("result/mc.json")).unwrap()).unwrap();
        assert_eq!(merged["cells"], whole["cells"]);
    }
    let mut seen = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().map(Result::unwrap) {
            seen.push(e.file_name().to_string_lossy().into_owned());
            if e.file_type().unwrap().is_dir() {
                stack.push(e.path());
            }
        }
    }
    assert!(seen.iter().all(|n| !n.starts_with("PWNED")), "a path ran as code: {seen:?}");
    let home = std::env::var("HOME").unwrap_or_default();
    assert!(!Path::new(&home).join("partials").exists() || home.is_empty());
}

/// Each bad input: exit status 2, one line on stderr naming the problem, no panic, no
/// output directory.
#[test]
fn bad_input_exits_2_with_one_line_naming_the_key() {
    let dir = scratch("bad");
    let write = |name: &str, body: &str| {
        let p = dir.join(name);
        std::fs::write(&p, body).unwrap();
        p.to_string_lossy().into_owned()
    };
    let missing = dir.join("nope.toml").to_string_lossy().into_owned();
    let malformed = write("malformed.toml", "name = \"m\"\n[comms\nt_com_s = 3\n");
    let unknown = write("unknown.toml", "name = \"u\"\n[comms]\nt_comm_s = 3.0\n");
    let wrong_type = write("type.toml", "name = \"t\"\n[sensors]\nrange_noise_m = \"big\"\n");
    let t_com = write("tcom.toml", "name = \"c\"\n[comms]\nt_com_s = 0.0\n");
    let runs0 = write("runs.toml", "name = \"r\"\nruns = 0\n");
    let nan = write("nan.toml", "name = \"n\"\n[mission]\ndt_s = nan\n");
    let negative = write("neg.toml", "name = \"g\"\n[sensors]\ndoppler_noise_m_s = -0.1\n");
    let sweep = write("sweep.toml", "name = \"s\"\n[sweep]\nt_com_s = [3.0, -6.0]\n");
    let not_a_dir = write("file.txt", "x");
    let escape = write("escape.toml", "name = \"../../x\"\n");
    let usbl_sea = write("usbl-sea.toml", "[sea.usbl]\nwave_roll_deg = 3.0\n");
    let no_sea = write("no-sea.toml", "name = \"x\"\n");
    let good_sea = write("good-sea.toml", "[sea.odometry]\nturn_scale = 0.01\n");
    let two_seas = write("two.toml", "[[sea.ranges]]\nbeacon = 1\n[[sea.ranges]]\nbeacon = 1\n");
    let huge = write("huge.toml", "name = \"huge\"\n[mission]\nduration_s = 25000000\n");
    let estimator = write("est.toml", "name = \"e\"\n[[estimators]]\nkind = \"rosb\"\ndistance_sigma_frac = 0.1\n");
    let builtin = |name: &str| text(&run(&["scenarios", "--show", name]).stdout);
    let particles = write(
        "particles.toml",
        &builtin("hoff2024")
            .replace("particles = 500000 ", "particles = 50000000 ")
            .replace("duration_s = 3600 ", "duration_s = 60 "),
    );
    let long_step = write("step.toml", "name = \"d\"\n[mission]\nduration_s = 60\ndt_s = 100\n");
    let crawl = write("crawl.toml", "name = \"c\"\n[mission]\nspeed_m_s = 1e-300\n");
    let deep = write("deep.toml", &builtin("rypkema-m1").replacen("depth_m = 2.5", "depth_m = 1e9", 1));
    let wide = write("wide.toml", "name = \"w\"\n[[estimators]]\nkind = \"rosb\"\n");
    let partial = dir.join("p");
    let o = run(&["mc", &wide, "--runs", "2", "--shard", "0/1", "--out", partial.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let good = std::fs::read_to_string(partial.join("partial-0-of-1.json")).unwrap();
    let shards = write("partial-0-of-1000000000.json", &good.replace("\"shards\":1,", "\"shards\":1000000000,"));
    let runs = write("partial-runs.json", &good.replace("\"runs\":2,", "\"runs\":1000000000,"));
    let plaza1 = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/plaza/plaza1.toml");
    let plaza1 = plaza1.to_str().unwrap();
    let out_dir = dir.join("should-not-exist");
    let out = out_dir.to_str().unwrap();
    let wav = out_dir.join("ping.wav").to_string_lossy().into_owned();
    let fifo = dir.join("fifo.toml").to_string_lossy().into_owned();
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());

    let cases: Vec<(Vec<&str>, &[&str])> = vec![
        // tuning what weighs no measurement
        (
            vec!["tune", plaza1, "--estimators", "dead-reckoning", "--out", out],
            &["dead-reckoning", "weighs 0 innovation(s)", "nothing to fit"],
        ),
        // memory: refused up front, not aborted
        (
            vec!["mc", &particles, "--runs", "2", "--threads", "2", "--memory-gib", "8", "--out", out],
            &["particles.toml", "9.7 GB", "memory budget is 8.6 GB", "particles", "--memory-gib"],
        ),
        (vec!["run", &particles, "--memory-gib", "4", "--out", out], &["particles.toml", "memory budget is 4.3 GB"]),
        (vec!["mc", "garin2024", "--memory-gib", "0"], &["--memory-gib", "> 0"]),
        (vec!["fleet", "rypkema-m1", "--memory-gib", "0.01", "--out", out], &["rypkema-m1", "recorded runs", "budget"]),
        (vec!["replay", plaza1, "--memory-gib", "0.01", "--out", out], &["replaying plaza1", "budget"]),
        // the smoother's graph and the filters' histories, which a replay does not hold
        (vec!["smooth", plaza1, "--memory-gib", "0.2", "--out", out], &["smoothing plaza1", "histories", "budget"]),
        (vec!["mc", "merge", partial.to_str().unwrap(), "--memory-gib", "1e-9", "--out", out], &["merging", "budget"]),
        (vec!["mc", &long_step, "--out", out], &["step.toml", "mission.dt_s", "duration"]),
        (vec!["mc", &crawl, "--out", out], &["crawl.toml", "mission.speed_m_s", "1e8 steps"]),
        (vec!["fleet", &deep, "--out", out], &["deep.toml", "auvs[0].depth_m", "signal.water_depth_m"]),
        (
            vec!["mc", "garin2024", "--runs", "2", "--shard", "12/13", "--out", out],
            &["--shard 12/13", "12 (cell, run)"],
        ),
        // merge: counts checked before use, only regular files read
        (vec!["mc", "merge", "/dev/zero", "--out", out], &["/dev/zero", "not a regular file"]),
        (vec!["mc", "merge", &shards, "--out", out], &["partial-0-of-1000000000.json", "shards 1000000000"]),
        (vec!["mc", "merge", &runs, "--out", out], &["partial-runs.json", "should hold 1000000000"]),
        (vec!["run", "garin2025", "--out", out], &["garin2025", "garin2024"]),
        (vec!["mc", &missing, "--out", out], &["nope.toml", "cannot open"]),
        // every reader of a file the user names: regular files only, never read without
        // bound (cfb7f93 grew to 4.2 GB on /dev/zero)
        (vec!["run", "/dev/zero", "--out", out], &["/dev/zero", "not a regular file"]),
        (vec!["fleet", "/dev/zero", "--out", out], &["/dev/zero", "not a regular file"]),
        (vec!["replay", "/dev/zero", "--out", out], &["/dev/zero", "not a regular file"]),
        (vec!["smooth", "/dev/zero", "--out", out], &["/dev/zero", "not a regular file"]),
        (vec!["tune", "/dev/zero", "--out", out], &["/dev/zero", "not a regular file"]),
        (vec!["sea-fit", "/dev/zero", "--out", out], &["/dev/zero", "not a regular file"]),
        (vec!["sea-fit", plaza1, "--window-s", "0", "--out", out], &["--window-s 0", "> 0"]),
        (vec!["sea-fit", plaza1, "--beacons", "9", "--out", out], &["--beacons", "9"]),
        (vec!["twin", "/dev/zero", "--sea", &no_sea, "--out", out], &["/dev/zero", "not a regular file"]),
        (vec!["twin", plaza1, "--sea", "/dev/zero", "--out", out], &["--sea /dev/zero", "not a regular file"]),
        (vec!["twin", plaza1, "--sea", &no_sea, "--out", out], &["no-sea.toml", "no [sea] table", "sea-fit"]),
        (vec!["twin", plaza1, "--sea", &usbl_sea, "--out", out], &["usbl-sea.toml", "sea.usbl", "leave it out"]),
        (vec!["twin", plaza1, "--sea", &two_seas, "--out", out], &["two.toml", "two entries for beacon 1"]),
        (vec!["twin", plaza1, "--sea", &malformed, "--out", out], &["--sea", "malformed.toml", "line 2"]),
        (vec!["twin", plaza1, "--sea", &no_sea, "--runs", "0", "--out", out], &["--runs", "0"]),
        (vec!["twin", plaza1, "--sea", &good_sea, "--beacons", "9", "--out", out], &["--beacons", "9"]),
        (
            vec!["twin", plaza1, "--sea", &good_sea, "--runs", "4", "--shard", "0/9", "--out", out],
            &["--shard 0/9", "4 runs", "at most 4"],
        ),
        (
            vec!["twin", plaza1, "--sea", &good_sea, "--merge", "/dev/zero", "--out", out],
            &["/dev/zero", "not a regular file"],
        ),
        (
            vec!["twin", plaza1, "--sea", &good_sea, "--merge", partial.to_str().unwrap(), "--out", out],
            &["not an onebeacon twin partial", "onebeacon-mc-partial/1"],
        ),
        (vec!["stream", "/dev/zero"], &["/dev/zero", "not a regular file"]),
        (vec!["replay", plaza1, "--estimators", "/dev/zero", "--out", out], &["/dev/zero", "not a regular file"]),
        (vec!["dsp", "simulate", "--config", "/dev/zero", "--out", &wav], &["/dev/zero", "not a regular file"]),
        (vec!["run", &fifo, "--out", out], &["fifo.toml", "not a regular file"]),
        (vec!["mc", &malformed, "--out", out], &["malformed.toml", "line 2"]),
        (vec!["mc", &unknown, "--out", out], &["unknown.toml", "t_comm_s", "t_com_s"]),
        (vec!["mc", &wrong_type, "--out", out], &["type.toml", "sensors.range_noise_m", "line 3"]),
        (vec!["run", &t_com, "--out", out], &["tcom.toml", "comms.t_com_s", "> 0"]),
        (vec!["mc", &runs0, "--out", out], &["runs.toml", "runs", "from 1"]),
        (vec!["mc", &nan, "--out", out], &["nan.toml", "mission.dt_s", "NaN"]),
        (vec!["mc", &negative, "--out", out], &["neg.toml", "sensors.doppler_noise_m_s", ">= 0"]),
        (vec!["mc", &sweep, "--out", out], &["sweep.toml", "sweep.t_com_s[1]"]),
        (vec!["mc", "garin2024", "--runs", "0", "--out", out], &["--runs", "0"]),
        (vec!["mc", "garin2024", "--threads", "0", "--out", out], &["--threads"]),
        (vec!["mc", "garin2024", "--seed", "abc", "--out", out], &["--seed", "abc"]),
        (vec!["run", "garin2024", "--out", &not_a_dir], &["file.txt", "not a directory"]),
        (vec!["scenarios", "--show", "nothing"], &["nothing", "garin2024"]),
        (vec!["guidance", "standoff", "--speed-m-s", "0", "--depths-m", "5"], &["--speed-m-s", "> 0"]),
        (vec!["guidance", "standoff", "--speed-m-s", "2", "--depths-m", "5,nan"], &["--depths-m", "nan"]),
        (vec!["guidance", "standoff", "--speed-m-s", "2"], &["--depths-m"]),
        (vec!["fly"], &["fly"]),
        (vec!["run", &escape], &["escape.toml", "name", "a name, not a path"]),
        (vec!["run", &huge, "--out", out], &["huge.toml", "100000000 steps", "GB"]),
        (
            vec!["run", &estimator, "--out", out],
            &["est.toml", "estimators[0].distance_sigma_frac", "applies to: log or planar stream"],
        ),
        (vec!["run", "hoff2024", "--message", "0", "--out", out], &["--message 0", "messages 1 to 900"]),
    ];
    for (args, needles) in cases {
        let o = run(&args);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: not one line: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        for n in needles {
            assert!(err.contains(n), "{args:?}: `{n}` not in: {err}");
        }
        assert!(o.stdout.is_empty(), "{args:?}: wrote to stdout");
        assert!(!out_dir.exists(), "{args:?}: left an output directory");
    }
}

#[test]
fn standoff_distance_grows_with_depth() {
    let out = run(&["guidance", "standoff", "--speed-m-s", "2", "--depths-m", "1,5,20,50", "--json"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(&text(&out.stdout)).unwrap();
    assert_eq!(v["reach_m"], 20.0);
    let d: Vec<f64> = v["standoffs"].as_array().unwrap().iter().map(|s| s["distance_m"].as_f64().unwrap()).collect();
    assert_eq!(d.len(), 4);
    assert!(d.windows(2).all(|w| w[1] > w[0]), "{d:?}");
}

const SHORT_SOUSA: &str = r#"
kind = "moving_beacon"
name = "short-sousa"
description = "five minutes of the sousa mission"
runs = 2
[mission]
duration_s = 300.0
[sweep]
path = ["stationary", "circular"]
depth_m = [5.0]
guidance = ["A", "static"]
"#;

#[test]
fn moving_beacon_run_and_mc() {
    let dir = scratch("sousa");
    let p = dir.join("short-sousa.toml");
    std::fs::write(&p, SHORT_SOUSA).unwrap();
    let scenario = p.to_str().unwrap();
    let out_dir = dir.join("run");
    let out = run(&["run", scenario, "--ping", "3", "--out", out_dir.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    for png in ["top_view.png", "error.png", "guidance.png"] {
        assert!(std::fs::read(out_dir.join(png)).unwrap().starts_with(b"\x89PNG"), "{png}");
    }
    let csv = std::fs::read_to_string(out_dir.join("trajectory.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(header.contains("beacon_north_m") && header.contains("range-ekf_down_m"), "{header}");
    assert_eq!(csv.lines().count(), 3002);

    let out = run(&["mc", scenario, "--json"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(&text(&out.stdout)).unwrap();
    let cells = v["cells"].as_array().unwrap();
    assert_eq!(cells.len(), 8); // 2 paths x 2 guidance x 2 estimators
    assert_eq!(cells[0]["sweep"]["path"], "stationary");
    assert_eq!(cells[0]["sweep"]["guidance"], "A");
    assert_eq!(cells[0]["sweep"]["depth_m"], 5.0);
    assert!(cells[0]["pcrb_rmse_m"].as_f64().unwrap() > 0.0);
    assert!(cells[0]["etd_mean_pct"].is_null()); // a stationary vehicle travels no distance

    let o = run(&["run", scenario, "--ping", "500", "--out", dir.join("none").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("--ping 500"));
    assert!(!dir.join("none").exists());
}

/// A short passive-USBL scenario: 2000 particles, 80 s (20 messages), REMUS 100 and
/// Otter in a current.
const SHORT_HOFF: &str = r#"kind = "passive_usbl"
name = "short-hoff"
runs = 2
[mission]
duration_s = 80
[auv]
vehicle = "remus100"
[asv]
vehicle = "otter"
[current]
speed_m_s = 0.1
[guidance]
planner_particles = 500
[[estimators]]
kind = "pf"
particles = 2000
[[estimators]]
kind = "bearing"
[sweep]
guidance = ["det", "static"]
"#;

/// `run` on a passive-USBL scenario draws the particle cloud at `--message`, the
/// planner's score and the autopilots; `mc --json` has one cell per guidance and
/// estimator, with a bound.
#[test]
fn passive_usbl_run_and_mc() {
    let dir = scratch("hoff");
    let p = dir.join("short-hoff.toml");
    std::fs::write(&p, SHORT_HOFF).unwrap();
    let scenario = p.to_str().unwrap();
    let out_dir = dir.join("run");
    let out = run(&["run", scenario, "--message", "5", "--ping", "0", "--out", out_dir.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    for png in ["top_view.png", "error.png", "guidance.png", "belief.png", "autopilots.png"] {
        assert!(std::fs::read(out_dir.join(png)).unwrap().starts_with(b"\x89PNG"), "{png}");
    }
    let csv = std::fs::read_to_string(out_dir.join("trajectory.csv")).unwrap();
    assert_eq!(csv.lines().count(), 22); // a header and steps 0 to 20
    let out = run(&["mc", scenario, "--json"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(&text(&out.stdout)).unwrap();
    let cells = v["cells"].as_array().unwrap();
    assert_eq!(cells.len(), 4);
    assert_eq!(
        (cells[0]["sweep"]["guidance"].as_str(), cells[2]["sweep"]["guidance"].as_str()),
        (Some("det"), Some("static"))
    );
    assert!(cells[0]["pcrb_rmse_m"].as_f64().unwrap() > 0.0);
    // the same cells with the lanes forced to the baseline instruction set (the
    // planner's and the filter's transcendental functions, the normal draws); an
    // instruction set it does not know is refused
    let o = bin().args(["mc", scenario, "--json"]).env("ONEBEACON_SIMD", "baseline").output().unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let baseline: serde_json::Value = serde_json::from_str(&text(&o.stdout)).unwrap();
    assert_eq!(baseline["cells"], v["cells"]);
    let o = bin().args(["mc", scenario, "--json"]).env("ONEBEACON_SIMD", "avx9").output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(text(&o.stderr).trim_end(), "error: ONEBEACON_SIMD=avx9: expected baseline, avx2 or avx512");
    let o = run(&["run", scenario, "--message", "21", "--out", dir.join("none").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("messages 1 to 20"), "{}", text(&o.stderr));
    assert!(!dir.join("none").exists());
}

fn write_wav(path: &Path, channels: u16, rate: u32, samples: &[f32]) {
    let spec =
        hound::WavSpec { channels, sample_rate: rate, bits_per_sample: 32, sample_format: hound::SampleFormat::Float };
    let mut w = hound::WavWriter::create(path, spec).unwrap();
    for s in samples {
        w.write_sample(*s).unwrap();
    }
    w.finalize().unwrap();
}

#[test]
fn dsp_simulate_then_process_recovers_the_truth() {
    let dir = scratch("dsp");
    let wav = dir.join("ping.wav");
    let out = run(&["dsp", "simulate", "--out", wav.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("ping.json")).unwrap()).unwrap();
    let res_dir = dir.join("res");
    let out = run(&["dsp", "process", wav.to_str().unwrap(), "--json", "--out", res_dir.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let est: serde_json::Value = serde_json::from_str(&text(&out.stdout)).unwrap();
    for key in ["range_m", "azimuth_deg", "inclination_deg", "mode"] {
        assert!(!est[key].is_null() && !truth[key].is_null(), "{key}");
    }
    assert_eq!(est["mode"], truth["mode"]);
    assert_eq!(est["detected"], true, "{est}");
    let d = |k: &str| (est[k].as_f64().unwrap() - truth[k].as_f64().unwrap()).abs();
    assert!(d("range_m") < 0.2, "{est} vs {truth}");
    assert!(d("azimuth_deg") < 5.0 && d("inclination_deg") < 5.0, "{est} vs {truth}");
    for f in ["range.csv", "range.png", "beam.png", "estimate.json"] {
        assert!(res_dir.join(f).exists(), "{f}");
    }
}

/// Silence, a DC offset and white noise are no ping: `detected: false`, no range, not
/// consistent (they used to give a "consistent" range).
#[test]
fn dsp_process_says_when_there_is_no_ping() {
    let dir = scratch("noping");
    let n = 5 * 8000;
    let mut state = 12345u64;
    let mut uniform = || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 11) as f32 / (1u64 << 53) as f32 - 0.5
    };
    let noise: Vec<f32> = (0..n).map(|_| 0.1 * uniform()).collect();
    for (name, samples) in [("zero", vec![0.0f32; n]), ("dc", vec![0.25f32; n]), ("noise", noise)] {
        let wav = dir.join(format!("{name}.wav"));
        write_wav(&wav, 5, 37_500, &samples);
        let o = run(&["dsp", "process", wav.to_str().unwrap(), "--json"]);
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        let est: serde_json::Value = serde_json::from_str(&text(&o.stdout)).unwrap();
        assert_eq!(est["detected"], false, "{name}: {est}");
        assert_eq!(est["consistent"], false, "{name}: {est}");
        assert!(est["range_m"].is_null(), "{name}: {est}");
    }
    // nor for a garin frame (silence gave range -2.3 m, "consistent"), which is found
    // at 40 dB with the truth's range
    let cfg = dir.join("frame.toml");
    std::fs::write(&cfg, "[waveform]\nkind = \"garin_frame\"\n[capture]\nfs_hz = 96153\nsamples = 52000\n").unwrap();
    let n = 5 * 52000;
    for (name, samples) in [("zero", vec![0.0f32; n]), ("noise", (0..n).map(|_| 0.1 * uniform()).collect())] {
        let wav = dir.join(format!("frame-{name}.wav"));
        write_wav(&wav, 5, 96153, &samples);
        let o = run(&["dsp", "process", wav.to_str().unwrap(), "--config", cfg.to_str().unwrap(), "--json"]);
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        let est: serde_json::Value = serde_json::from_str(&text(&o.stdout)).unwrap();
        assert_eq!(est["detected"], false, "frame {name}: {est}");
        assert!(est["range_m"].is_null() && est["radial_speed_m_s"].is_null(), "frame {name}: {est}");
    }
}

/// A recording longer than `capture.samples` is cut into captures processed one by one,
/// each as the single capture would be; a bad sample anywhere is refused before any
/// line is given.
#[test]
fn dsp_process_cuts_a_recording_into_captures() {
    let dir = scratch("recording");
    let wav = dir.join("ping.wav");
    assert!(run(&["dsp", "simulate", "--out", wav.to_str().unwrap()]).status.success());
    let single = run(&["dsp", "process", wav.to_str().unwrap(), "--json"]);
    let single: serde_json::Value = serde_json::from_str(&text(&single.stdout)).unwrap();
    let ping: Vec<f32> = hound::WavReader::open(&wav).unwrap().samples::<f32>().map(Result::unwrap).collect();
    // ping, silence, ping, and half a capture of silence (padded with zeros)
    let mut recording = ping.clone();
    recording.extend(vec![0.0; ping.len()]);
    recording.extend(&ping);
    recording.extend(vec![0.0; ping.len() / 2]);
    let long = dir.join("recording.wav");
    write_wav(&long, 5, 37_500, &recording);
    let out_dir = dir.join("out");
    let o = run(&["dsp", "process", long.to_str().unwrap(), "--json", "--out", out_dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let lines: Vec<serde_json::Value> = text(&o.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 4);
    for (k, line) in lines.iter().enumerate() {
        assert_eq!(line["capture"], k);
        assert!((line["t_s"].as_f64().unwrap() - k as f64 * 8000.0 / 37_500.0).abs() < 1e-12);
        assert_eq!(line["detected"], k % 2 == 0, "{line}");
        if k % 2 == 0 {
            for key in ["range_m", "azimuth_deg", "inclination_deg", "mode", "consistent"] {
                assert_eq!(line[key], single[key], "{key}");
            }
        }
    }
    let csv = std::fs::read_to_string(out_dir.join("captures.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5);
    // a sample that is not a number in the third capture (frame 2 x 8000 + 7 / 5, channel
    // 7 % 5): exit 2, and no line at all
    recording[2 * ping.len() + 7] = f32::NAN;
    write_wav(&long, 5, 37_500, &recording);
    let o = run(&["dsp", "process", long.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("sample 16001 of channel 2 is not a number"), "{}", text(&o.stderr));
    assert!(o.stdout.is_empty());
}

#[test]
fn bad_wav_input_exits_2_with_one_line() {
    let dir = scratch("badwav");
    let good = dir.join("good.wav");
    assert!(run(&["dsp", "simulate", "--out", good.to_str().unwrap()]).status.success());
    let bytes = std::fs::read(&good).unwrap();
    let truncated = dir.join("truncated.wav");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2 + 3]).unwrap();
    let empty = dir.join("empty.wav");
    write_wav(&empty, 5, 37_500, &[]);
    let nan = dir.join("nan.wav");
    let mut s = vec![0.01f32; 5 * 2000];
    s[777] = f32::NAN;
    write_wav(&nan, 5, 37_500, &s);
    let clipped = dir.join("clipped.wav");
    let mut s = vec![0.01f32; 5 * 2000];
    s[10] = 1.0;
    s[11] = -1.0;
    write_wav(&clipped, 5, 37_500, &s);
    let rate = dir.join("rate.wav");
    write_wav(&rate, 5, 48_000, &vec![0.01f32; 5 * 2000]);
    let four = dir.join("four.wav");
    write_wav(&four, 4, 37_500, &vec![0.01f32; 4 * 2000]);
    let notwav = dir.join("notwav.wav");
    std::fs::write(&notwav, "hello").unwrap();
    let out_dir = dir.join("nothing");
    let cases: Vec<(&Path, &[&str])> = vec![
        (&truncated, &["truncated.wav", "truncated"]),
        (&empty, &["empty.wav", "no samples"]),
        (&nan, &["nan.wav", "not a number"]),
        (&clipped, &["clipped.wav", "2 samples at full scale"]),
        (&rate, &["rate.wav", "48000", "37500"]),
        (&four, &["four.wav", "4 channels", "5 elements"]),
        (&notwav, &["notwav.wav", "not a readable WAV"]),
    ];
    for (wav, needles) in cases {
        let o = run(&["dsp", "process", wav.to_str().unwrap(), "--out", out_dir.to_str().unwrap()]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{wav:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        for n in needles {
            assert!(err.contains(n), "`{n}` not in {err}");
        }
        assert!(!out_dir.exists());
    }
    let o = run(&["dsp", "simulate", "--out", dir.join("ping.mp3").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn dsp_garin_frame_gives_range_and_doppler_speed() {
    let dir = scratch("garin-frame");
    let cfg = dir.join("frame.toml");
    std::fs::write(
        &cfg,
        "[waveform]\nkind = \"garin_frame\"\n[capture]\nfs_hz = 96153\nsamples = 52000\n[geometry]\nradial_speed_m_s = -2.0\n[noise]\nsnr_db = 40\n",
    )
    .unwrap();
    let wav = dir.join("frame.wav");
    let out = run(&["dsp", "simulate", "--config", cfg.to_str().unwrap(), "--out", wav.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("frame.json")).unwrap()).unwrap();
    let out = run(&["dsp", "process", wav.to_str().unwrap(), "--config", cfg.to_str().unwrap(), "--json"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let est: serde_json::Value = serde_json::from_str(&text(&out.stdout)).unwrap();
    assert!(est["mode"].is_null());
    assert_eq!(est["detected"], true, "{est}");
    let d = |k: &str| (est[k].as_f64().unwrap() - truth[k].as_f64().unwrap()).abs();
    assert!(d("range_m") < 0.1, "{est} vs {truth}");
    assert!(d("radial_speed_m_s") < 0.05, "{est} vs {truth}");
    // a chirp rate cannot carry the frame
    std::fs::write(&cfg, "[waveform]\nkind = \"garin_frame\"\n").unwrap();
    let o = run(&["dsp", "simulate", "--config", cfg.to_str().unwrap(), "--out", wav.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("capture.fs_hz"));
}

/// A stdout that cannot be written (a full disk) is one line of error and exit 1, not
/// a panic.
#[test]
fn full_stdout_is_an_error_not_a_panic() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else { return };
    let dir = scratch("full");
    let out = dir.join("o");
    for args in [
        vec!["scenarios"],
        vec!["guidance", "standoff", "--speed-m-s", "2", "--depths-m", "1,5"],
        vec!["run", "garin2024", "--out", out.to_str().unwrap()],
    ] {
        let o = bin().args(&args).stdout(full.try_clone().unwrap()).output().unwrap();
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("cannot write to stdout") || err.contains("No space left"), "{args:?}: {err}");
        // one line of error; the run's findings (warnings) may come before it
        assert_eq!(err.trim().lines().filter(|l| !l.starts_with("warning: ")).count(), 1, "{args:?}: {err}");
    }
}

/// The names in `dir`, sorted.
fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

/// An earlier onebeacon output is replaced whole: no stale file of an older run stays,
/// and no staging directory is left beside it.
#[test]
fn out_replaces_an_earlier_output_whole() {
    let dir = scratch("replace");
    let scenario = short_scenario(&dir);
    let out = dir.join("o");
    let o = run(&["mc", &scenario, "--runs", "2", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(out.join("mc.json").is_file());
    let o = run(&["run", &scenario, "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(
        names_in(&out),
        [
            ".onebeacon-output",
            "error.png",
            "error.svg",
            "summary.json",
            "top_view.png",
            "top_view.svg",
            "trajectory.csv"
        ]
    );
    assert!(names_in(&dir).iter().all(|n| !n.contains("partial")), "{:?}", names_in(&dir));
}

/// `--out` never removes what onebeacon did not write: a directory holding other files
/// (a log's own directory, a thesis), the working directory or one that holds it, and
/// a symbolic link are refused before any work, with one line and exit status 2, and
/// every file stays as it was.
#[test]
fn out_never_takes_what_onebeacon_did_not_write() {
    let dir = scratch("foreign");
    let scenario = short_scenario(&dir);
    let refused = |args: &[&str], cwd: &Path, needle: &str| {
        let o = bin().args(args).current_dir(cwd).output().unwrap();
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    };
    // the user's own directory
    let thesis = dir.join("u");
    std::fs::create_dir_all(&thesis).unwrap();
    std::fs::write(thesis.join("thesis.tex"), "my thesis").unwrap();
    refused(&["run", &scenario, "--out", thesis.to_str().unwrap()], &dir, "thesis.tex");
    assert_eq!(names_in(&thesis), ["thesis.tex"]);
    // a log replayed into its own directory
    let plaza = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/plaza");
    let dl = dir.join("dl");
    std::fs::create_dir_all(&dl).unwrap();
    for e in std::fs::read_dir(&plaza).unwrap().map(Result::unwrap) {
        std::fs::copy(e.path(), dl.join(e.file_name())).unwrap();
    }
    let before = names_in(&dl);
    let log = dl.join("plaza1.toml");
    refused(&["replay", log.to_str().unwrap(), "--out", dl.to_str().unwrap()], &dir, "an input of this command");
    assert_eq!(names_in(&dl), before);
    // an earlier output with a file of the user's added
    let out = dir.join("o");
    assert!(run(&["run", &scenario, "--out", out.to_str().unwrap()]).status.success());
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    refused(&["run", &scenario, "--out", out.to_str().unwrap()], &dir, "notes.txt");
    assert_eq!(std::fs::read_to_string(out.join("notes.txt")).unwrap(), "mine");
    // the working directory, and a parent of it, even when they are outputs
    std::fs::remove_file(out.join("notes.txt")).unwrap();
    refused(&["run", &scenario, "--out", "."], &out, "working directory");
    let inner = out.join("..").join("u");
    refused(&["mc", &scenario, "--runs", "1", "--out", ".."], &inner, "working directory");
    assert_eq!(names_in(&thesis), ["thesis.tex"]);
    // a symbolic link
    #[cfg(unix)]
    {
        let link = dir.join("link");
        std::os::unix::fs::symlink(&thesis, &link).unwrap();
        refused(&["run", &scenario, "--out", link.to_str().unwrap()], &dir, "symbolic link");
        assert_eq!(names_in(&thesis), ["thesis.tex"]);
    }
    // a file beside others: `dsp simulate` does not overwrite a recording of the user's
    let wav = thesis.join("rec.wav");
    std::fs::write(&wav, "RIFF of the user's").unwrap();
    refused(&["dsp", "simulate", "--out", wav.to_str().unwrap()], &dir, "not written by onebeacon");
    assert_eq!(std::fs::read_to_string(&wav).unwrap(), "RIFF of the user's");
    // nothing was staged anywhere
    assert!(names_in(&dir).iter().all(|n| !n.contains("partial")), "{:?}", names_in(&dir));
}

/// A filter started with an absurd uncertainty (1e308 m) is drawn, clipped, instead of
/// hanging in the plotter's tick search (it once did, forever).
#[test]
fn absurd_values_are_plotted_not_hung() {
    let dir = scratch("absurd");
    let sousa = text(&run(&["scenarios", "--show", "sousa"]).stdout)
        .replace("position_sigma_m = 1.0 ", "position_sigma_m = 1e308 ")
        .replace("duration_s = 7200", "duration_s = 30");
    assert!(sousa.contains("position_sigma_m = 1e308"));
    let p = dir.join("absurd.toml");
    std::fs::write(&p, sousa).unwrap();
    let mut child = bin()
        .args(["run", p.to_str().unwrap(), "--out", dir.join("o").to_str().unwrap()])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if started.elapsed().as_secs() > 60 {
            let _ = child.kill();
            panic!("run did not end in 60 s (a 30 s mission takes well under 1 s)");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    assert!(status.success());
    assert!(std::fs::read(dir.join("o/error.png")).unwrap().starts_with(b"\x89PNG"));
}

/// A long `mc garin2024 --out out` (stderr piped), once its staging directory
/// `.NAME.partial-PID` beside `out` holds its marker: the child and that directory.
#[cfg(unix)]
fn long_mc_staged(out: &Path) -> (std::process::Child, PathBuf) {
    let child = bin()
        .args(["mc", "garin2024", "--runs", "2000", "--out", out.to_str().unwrap()])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let name = out.file_name().unwrap().to_string_lossy();
    let staging = out.with_file_name(format!(".{name}.partial-{}", child.id()));
    let waited = std::time::Instant::now();
    while !staging.join(".onebeacon-output").exists() {
        assert!(waited.elapsed().as_secs() < 60, "no staging directory appeared");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    (child, staging)
}

/// A staging directory that a killed run left (SIGKILL: no handler runs) is removed by
/// the next run that writes beside it; one of a live process is not.
#[cfg(unix)]
#[test]
fn a_killed_runs_staging_directory_is_cleaned_later() {
    let dir = scratch("stale");
    let scenario = short_scenario(&dir);
    let out = dir.join("o");
    let (child, stale) = long_mc_staged(&out);
    // SAFETY: kill(2) on our own child's pid
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGKILL) }, 0);
    child.wait_with_output().unwrap();
    assert!(stale.exists(), "SIGKILL leaves the staging directory");
    // a live process's staging directory, as its run writes it
    let live = dir.join(format!(".o.partial-{}", std::process::id()));
    std::fs::create_dir_all(&live).unwrap();
    std::fs::copy(stale.join(".onebeacon-output"), live.join(".onebeacon-output")).unwrap();
    let o = run(&["run", &scenario, "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(!stale.exists(), "the killed run's staging directory is removed");
    assert!(live.exists(), "a live process's staging directory stays");
}

/// A signal while `--out` is being computed removes the staging directory and leaves
/// the existing output directory as it was (exit status 128 + the signal).
#[cfg(unix)]
#[test]
fn a_signal_leaves_no_partial_output() {
    for (signal, name) in [(libc::SIGINT, "int"), (libc::SIGTERM, "term")] {
        let dir = scratch(&format!("signal-{name}"));
        let out = dir.join("res");
        let scenario = short_scenario(&dir);
        let first = run(&["mc", &scenario, "--runs", "1", "--out", out.to_str().unwrap()]);
        assert!(first.status.success(), "{}", text(&first.stderr));
        let old = std::fs::read(out.join("mc.json")).unwrap();
        let (child, partial) = long_mc_staged(&out);
        // SAFETY: kill(2) on our own child's pid
        assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
        let o = child.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(128 + signal), "{name}: {}", text(&o.stderr));
        assert!(!partial.exists(), "{name}: the staging directory is removed");
        assert_eq!(std::fs::read(out.join("mc.json")).unwrap(), old, "{name}: the earlier output is as it was");
        assert_eq!(names_in(&dir), ["res", "short.toml"], "{name}: nothing else beside the output");
    }
}
