//! `tadslc eval --shard` on the job engine it is for: a one-node Slurm (Debian's slurm-wlm and
//! munge, started and stopped by `tests/slurm/cluster.sh` in a temporary directory) runs
//! `sbatch --array=0-3`, a shard per task, and `merge` of their results files prints byte for
//! byte (`cmp`) the table of the command run whole; a shard cancelled midway (`scancel`) and
//! submitted again redoes only the scenarios its journal lacks (`resumed K of M`). One cluster
//! at a time, small settings. Skipped loudly when Slurm is not installed or cannot start, unless
//! `TAD_REQUIRE_SLURM=1` (CI), which makes that a failure; `TAD_SLURM_PATH` replaces where its
//! programs are looked for.

mod common;
use common::*;

use std::ffi::OsString;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// The array's settings: small, the same for every run.
const ARRAY: &[&str] = &["eval", "examples", "--region", "los_angeles,new_york_city", "-n", "4", "--samples", "10"];

/// The cancelled shard's: 24 scenarios of a third of a second or more each (debug build), so it is
/// still running when its journal has one.
const LONGER: &[&str] = &["eval", "examples", "--region", "los_angeles,new_york_city", "-n", "8", "--samples", "40"];

/// A job's time limit (and the tests' bound on waiting for one).
const JOB_LIMIT: Duration = Duration::from_secs(300);

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The tests share two cores and one node name: one cluster at a time.
fn one_at_a_time() -> MutexGuard<'static, ()> {
    static LOCK: Mutex<()> = Mutex::new(());
    LOCK.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

fn required() -> bool {
    std::env::var_os("TAD_REQUIRE_SLURM").is_some_and(|v| v == "1")
}

fn skip(why: &str) -> Option<Cluster> {
    assert!(!required(), "Slurm cannot run here and TAD_REQUIRE_SLURM=1: {why}");
    // straight to standard error, which the test harness does not capture: seen in every run
    let (first, details) = why.split_once('\n').unwrap_or((why, ""));
    let _ = writeln!(std::io::stderr(), "skipped: {first} (TAD_REQUIRE_SLURM=1 makes this a failure)\n{details}");
    None
}

/// Where Slurm's and munge's programs are looked for: `TAD_SLURM_PATH`, else PATH and the
/// daemons' directories (not on a user's PATH on Debian).
fn slurm_path() -> Vec<PathBuf> {
    match std::env::var_os("TAD_SLURM_PATH") {
        Some(dirs) => std::env::split_paths(&dirs).collect(),
        None => {
            let mut dirs: Vec<PathBuf> =
                std::env::var_os("PATH").map(|p| std::env::split_paths(&p).collect()).unwrap_or_default();
            dirs.extend(["/usr/sbin", "/sbin"].map(PathBuf::from));
            dirs
        }
    }
}

/// A running one-node cluster; stopped (every daemon `cluster.sh start` started) when dropped,
/// on a failure too.
struct Cluster {
    dir: PathBuf,
    /// `slurm_path()` then PATH: the daemons, the clients and a shell's tools.
    path: OsString,
    /// What `cluster.sh start` printed to use: `SLURM_CONF`.
    env: Vec<(String, String)>,
}

impl Cluster {
    fn start(name: &str) -> Option<Cluster> {
        let dirs = slurm_path();
        for program in ["slurmctld", "slurmd", "munged", "sbatch"] {
            if !dirs.iter().any(|d| d.join(program).is_file()) {
                return skip(&format!("{program} not found (apt-get install slurm-wlm munge)"));
            }
        }
        let search = std::env::join_paths(
            dirs.iter().cloned().chain(std::env::var_os("PATH").iter().flat_map(std::env::split_paths)),
        )
        .unwrap();
        // short: munged's socket is in it
        let dir = std::env::temp_dir().join(format!("tadsl-slurm-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let started = Instant::now();
        let out = Command::new("bash")
            .arg(repo().join("tests/slurm/cluster.sh"))
            .args(["start", path(&dir)])
            .env("PATH", &search)
            .output()
            .expect("bash runs");
        // a failed start has stopped what it started and printed the daemons' logs
        if !out.status.success() {
            let _ = std::fs::remove_dir_all(&dir);
            return skip(&format!("the one-node Slurm cluster did not start:\n{}", stderr(&out)));
        }
        let env = stdout(&out)
            .lines()
            .filter_map(|l| l.strip_prefix("export ")?.split_once('='))
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        eprint!("{}", stderr(&out));
        eprintln!("cluster started in {:.1} s", started.elapsed().as_secs_f64());
        Some(Cluster { dir, path: search, env })
    }

    fn command(&self, program: &str) -> Command {
        let mut command = Command::new(program);
        command.env("PATH", &self.path).envs(self.env.iter().map(|(k, v)| (k.as_str(), v.as_str())));
        command
    }

    /// `program args`, which must succeed.
    fn run(&self, program: &str, args: &[&str]) -> String {
        let out: Output = self.command(program).args(args).output().unwrap_or_else(|e| panic!("{program}: {e}"));
        assert!(out.status.success(), "{program} {args:?}: {}{}", stdout(&out), stderr(&out));
        stdout(&out)
    }

    /// Asserts what `sinfo` says of the node: idle, ready for a job.
    fn assert_idle(&self) {
        let node = self.run("sinfo", &["-h", "-N", "-o", "%N %t"]);
        assert!(node.trim().ends_with(" idle"), "the node is idle before a job is submitted: {node}");
    }

    /// `sbatch --parsable ARGS SCRIPT`: the job's id.
    fn submit(&self, args: &[&str], script: &Path) -> String {
        let out = self.run("sbatch", &[&["--parsable"][..], args, &[path(script)]].concat());
        let id = out.trim().split(';').next().unwrap().to_string();
        eprintln!("submitted job {id}: sbatch {}", args.join(" "));
        id
    }

    /// Whether `job` (`12`, every task of array 12, or `12_3`) still has a task pending or running.
    fn queued(&self, job: &str) -> bool {
        let out = self.command("squeue").args(["-h", "-j", job, "-o", "%i %T"]).output().unwrap();
        // a job that left the controller's memory is an error: not queued
        out.status.success() && !stdout(&out).trim().is_empty()
    }

    /// Waits until `job` has left the queue; `ArrayTaskId JobState ExitCode` of each task.
    fn wait(&self, job: &str, logs: &Path) -> Vec<String> {
        let started = Instant::now();
        while self.queued(job) {
            assert!(started.elapsed() < JOB_LIMIT, "job {job} still queued after {JOB_LIMIT:?}\n{}", self.logs(logs));
            std::thread::sleep(Duration::from_millis(200));
        }
        let fields = |line: &str, keys: &[&str]| -> String {
            keys.iter()
                .map(|k| line.split(' ').find_map(|f| f.strip_prefix(&format!("{k}="))).unwrap_or("?").to_string())
                .collect::<Vec<_>>()
                .join(" ")
        };
        let states: Vec<String> = self
            .run("scontrol", &["-o", "show", "job", job])
            .lines()
            .map(|l| fields(l, &["ArrayTaskId", "JobState", "ExitCode"]))
            .collect();
        eprintln!("job {job} ended after {:.1} s: {states:?}", started.elapsed().as_secs_f64());
        states
    }

    /// The jobs' output files in `dir` and the end of the daemons' logs: what a failure shows.
    fn logs(&self, dir: &Path) -> String {
        let mut text = String::new();
        let mut outputs: Vec<PathBuf> = std::fs::read_dir(dir)
            .map(|d| d.flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|x| x == "out")).collect())
            .unwrap_or_default();
        outputs.sort();
        for log in outputs.iter().chain(&[self.dir.join("slurmctld.log"), self.dir.join("slurmd.log")]) {
            let content = std::fs::read_to_string(log).unwrap_or_default();
            let lines: Vec<&str> = content.lines().collect();
            text += &format!("--- {} (last lines)\n", log.display());
            for line in &lines[lines.len().saturating_sub(30)..] {
                text += &format!("{line}\n");
            }
        }
        text
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let out = Command::new("bash")
            .arg(repo().join("tests/slurm/cluster.sh"))
            .args(["stop", path(&self.dir)])
            .env("PATH", &self.path)
            .output();
        match out {
            Ok(out) => eprint!("{}", stderr(&out)),
            Err(e) => eprintln!("cluster.sh stop {}: {e}", self.dir.display()),
        }
        if std::thread::panicking() {
            eprintln!("the cluster's configuration and logs are in {}", self.dir.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.dir);
        }
    }
}

/// A batch script running shard `$SLURM_ARRAY_TASK_ID/shards` of `eval` into `out`.
fn batch_script(out: &Path, eval: &[&str], shards: usize) -> PathBuf {
    let script = out.join("eval.sbatch");
    let text = format!(
        "#!/bin/sh\n\
         echo \"task $SLURM_ARRAY_TASK_ID of array $SLURM_ARRAY_JOB_ID (job $SLURM_JOB_ID) on $(hostname -s)\" >&2\n\
         exec '{}' {} --shard \"$SLURM_ARRAY_TASK_ID/{shards}\" --out '{}'\n",
        env!("CARGO_BIN_EXE_tadslc"),
        eval.join(" "),
        path(out)
    );
    std::fs::write(&script, text).unwrap();
    script
}

/// The flags of every submission: the repository as working directory (the corpus is
/// `examples`), an output file per task.
fn sbatch_args(out: &Path) -> Vec<String> {
    vec![
        "--job-name=tadsl-eval".into(),
        format!("--chdir={}", path(&repo())),
        format!("--output={}/slurm-%A_%a.out", path(out)),
        format!("--time={}", JOB_LIMIT.as_secs() / 60),
    ]
}

/// The table of the command run whole, outside Slurm, in `format`: written to `dir/whole.FORMAT`.
fn whole(eval: &[&str], format: &str, dir: &Path) -> PathBuf {
    let started = Instant::now();
    let out_dir = dir.join(format!("whole-{format}"));
    let out = tadslc(&[eval, &["--format", format, "--out", path(&out_dir)]].concat(), "");
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    eprintln!("the whole run ({format}) took {:.1} s", started.elapsed().as_secs_f64());
    let file = dir.join(format!("whole.{format}"));
    std::fs::write(&file, out.stdout).unwrap();
    file
}

/// `tadslc merge FILES --format FORMAT` into `dir/merged.FORMAT`, then `cmp` with `expected`.
fn merge_equals(files: &[PathBuf], format: &str, expected: &Path, cluster: &Cluster, logs: &Path) {
    let names: Vec<&str> = files.iter().map(|f| path(f)).collect();
    let merged = tadslc(&[&["merge"][..], &names, &["--format", format]].concat(), "");
    assert_eq!(code(&merged), 0, "{}\n{}", stderr(&merged), cluster.logs(logs));
    let file = expected.with_file_name(format!("merged.{format}"));
    std::fs::write(&file, &merged.stdout).unwrap();
    let cmp = Command::new("cmp").args([path(&file), path(expected)]).output().expect("cmp runs");
    assert!(
        cmp.status.success(),
        "the merged table differs from the whole run's: {}{}\n--- merged\n{}\n--- whole\n{}\n{}",
        stdout(&cmp),
        stderr(&cmp),
        stdout(&merged),
        std::fs::read_to_string(expected).unwrap(),
        cluster.logs(logs)
    );
    eprintln!("cmp {} {}: identical ({} bytes)", file.display(), expected.display(), merged.stdout.len());
}

/// The scenarios a journal has: its whole lines (ended by a newline, as a kill may cut the
/// last one short) that are a unit's entry, not the head line naming the setup.
fn journal_units(file: &Path) -> usize {
    let text = std::fs::read_to_string(file).unwrap_or_default();
    text.split_inclusive('\n')
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l.strip_suffix('\n')?).ok())
        .filter(|entry| entry.get("unit").is_some())
        .count()
}

#[test]
fn a_job_array_merges_to_the_unsharded_table() {
    let _one = one_at_a_time();
    let Some(cluster) = Cluster::start("array") else { return };
    let dir = scratch("slurm-array");
    let out = dir.join("shards");
    std::fs::create_dir_all(&out).unwrap();
    let whole_md = whole(ARRAY, "markdown", &dir);
    let whole_json = whole(ARRAY, "json", &dir);

    cluster.assert_idle();
    let started = Instant::now();
    let script = batch_script(&out, ARRAY, 4);
    let args = sbatch_args(&out);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let job = cluster.submit(&[&["--array=0-3"][..], &args].concat(), &script);
    let states = cluster.wait(&job, &out);
    assert_eq!(states.len(), 4, "{states:?}");
    assert!(states.iter().all(|s| s.ends_with("COMPLETED 0:0")), "{states:?}\n{}", cluster.logs(&out));
    eprintln!("the array ran in {:.1} s; the log of its task 0:", started.elapsed().as_secs_f64());
    eprint!("{}", std::fs::read_to_string(out.join(format!("slurm-{job}_0.out"))).unwrap_or_default());

    let files: Vec<PathBuf> = (0..4).map(|i| out.join(format!("results.{i}-of-4.json"))).collect();
    merge_equals(&files, "markdown", &whole_md, &cluster, &out);
    merge_equals(&files, "json", &whole_json, &cluster, &out);
}

/// eval's journal: with `--out DIR` a shard appends a line per finished scenario to
/// `DIR/results.I-of-N.jsonl` and, started again with the same setup, runs only the scenarios
/// missing from it, printing `resumed K of M scenarios from PATH` on stderr.
#[test]
fn a_cancelled_shard_resubmitted_redoes_only_what_it_had_not_written() {
    let _one = one_at_a_time();
    let Some(cluster) = Cluster::start("resume") else { return };
    let dir = scratch("slurm-resume");
    let out = dir.join("shards");
    std::fs::create_dir_all(&out).unwrap();
    let whole_md = whole(LONGER, "markdown", &dir);

    cluster.assert_idle();
    let script = batch_script(&out, LONGER, 2);
    let args = sbatch_args(&out);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let job = cluster.submit(&[&["--array=0-1"][..], &args].concat(), &script);
    let task = format!("{job}_1");
    let journal = out.join("results.1-of-2.jsonl");
    let results = out.join("results.1-of-2.json");
    // cancel shard 1 once its journal has a scenario, before its results file is written
    let started = Instant::now();
    loop {
        if journal_units(&journal) >= 1 && !results.exists() {
            break;
        }
        assert!(
            cluster.queued(&task) && !results.exists(),
            "shard 1/2 ended without a scenario in its journal {}\n{}",
            journal.display(),
            cluster.logs(&out)
        );
        assert!(started.elapsed() < JOB_LIMIT, "no line in {} after {JOB_LIMIT:?}", journal.display());
        std::thread::sleep(Duration::from_millis(50));
    }
    cluster.run("scancel", &[&task]);
    eprintln!(
        "cancelled {task} with {} scenario(s) in its journal after {:.1} s",
        journal_units(&journal),
        started.elapsed().as_secs_f64()
    );
    let states = cluster.wait(&task, &out);
    assert!(states.iter().all(|s| s.contains("CANCELLED")), "{states:?}");
    assert!(!results.exists(), "shard 1/2 finished before it was cancelled: give it more work (LONGER)");
    let written = journal_units(&journal);

    let again = cluster.submit(&[&["--array=1"][..], &args].concat(), &script);
    let states = cluster.wait(&again, &out);
    assert!(states.iter().all(|s| s.ends_with("COMPLETED 0:0")), "{states:?}\n{}", cluster.logs(&out));
    let states = cluster.wait(&job, &out);
    assert!(states.iter().any(|s| s == "0 COMPLETED 0:0"), "shard 0/2: {states:?}\n{}", cluster.logs(&out));

    // the resubmitted shard's stderr (its output file) says what it took from the journal
    let log = std::fs::read_to_string(out.join(format!("slurm-{again}_1.out"))).unwrap();
    eprintln!("the resubmitted shard's log:\n{log}");
    let resumed =
        log.lines().find(|l| l.starts_with("resumed ")).unwrap_or_else(|| panic!("no `resumed` line:\n{log}"));
    let words: Vec<&str> = resumed.split(' ').collect();
    assert!(
        words.len() == 7 && words[2] == "of" && words[4] == "scenarios" && words[5] == "from",
        "`resumed K of M scenarios from PATH`: {resumed}"
    );
    assert!(words[6].starts_with('`') && words[6].ends_with("results.1-of-2.jsonl`"), "{resumed}");
    let (k, m): (usize, usize) = (words[1].parse().unwrap(), words[3].parse().unwrap());
    assert!(0 < k && k < m, "some but not all of the shard's scenarios were done: {resumed}");
    assert_eq!(k, written, "every scenario the journal had is taken: {resumed}");
    let shard: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&results).unwrap()).unwrap();
    let total: u64 = shard["scenarios"].as_object().unwrap().values().map(|c| c.as_u64().unwrap()).sum();
    assert_eq!(m as u64, total, "M is the shard's scenarios: {resumed}");
    assert_eq!(journal_units(&journal), m, "the resumed shard ran only the {} scenarios it lacked", m - k);

    let files: Vec<PathBuf> = (0..2).map(|i| out.join(format!("results.{i}-of-2.json"))).collect();
    merge_equals(&files, "markdown", &whole_md, &cluster, &out);
}
