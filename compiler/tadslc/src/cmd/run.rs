//! `tadslc run`: scenarios run in the runtime against ego policies, scored with SafeBench's
//! metrics.
//!
//! Inputs are scenario files (checked, resolved, laid out and lowered to bytecode in memory,
//! the path `build --target bytecode` takes) or `.tadc` files (loaded and verified). Each
//! (scenario, ego, seed) is one episode with the parameters sampled from the seed. A file with
//! errors is reported and skipped (status 1); a corrupt `.tadc` too (status 2); the others
//! still run. Episodes are independent and deterministic.

use std::io::Write;
use std::ops::Range;
use std::path::PathBuf;

use crate::output::CliError;
use crate::{Status, errln, out, outln};
use tad_eval::record::{self, Played};
use tad_metrics::Mode;
use tad_runtime::{EventKind, Options};

/// What `run` prints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum RunFormat {
    Table,
    Json,
}

/// `tadslc run`'s arguments.
#[derive(clap::Args)]
pub struct RunArgs {
    /// Scenario files or directories (searched recursively for *.tad and *.yaml), or
    /// `.tadc` bytecode files
    #[arg(required = true)]
    pub paths: Vec<PathBuf>,
    /// The ego policies, comma-separated or repeated: `idm`, `naive`, the shipped models
    /// `ppo`, `sac`, `td3`, `learned:PATH` (an actor in safetensors: `train-ego`'s, or
    /// SafeBench's SAC), `external:CMD` (a process answering JSON lines, `spec/runtime.md`)
    #[arg(long = "ego", default_value = "idm,naive", value_parser = crate::EgoNames)]
    pub egos: Vec<String>,
    /// Seeds `A..B` (B excluded, as in Rust), `A..=B` (B included) or one seed `A`
    #[arg(long, default_value = "0..3", value_parser = parse_seeds)]
    pub seeds: std::ops::Range<u64>,
    /// Output format: a table for people, or JSON lines (one object per episode, then
    /// one aggregate object per ego)
    #[arg(long, value_enum, default_value_t = RunFormat::Table)]
    pub format: RunFormat,
    /// Write every actor's pose at every step as JSON lines
    #[arg(long, value_name = "FILE")]
    pub trace: Option<PathBuf>,
    /// Draw the first episode to FILE: `.svg` (a figure), `.png` (where it ended) or `.gif`
    /// (an animation); or, given a directory (or a path without an extension, made a
    /// directory), every episode as DIR/SCENARIO.EGO.seedN.svg
    #[arg(long, value_name = "FILE|DIR", value_parser = picture_path)]
    pub render: Option<PathBuf>,
    /// Score as SafeBench's scorer does, quirks included (TS 0 when nothing completes,
    /// yaw not unwrapped, off-road never ends an episode)
    #[arg(long)]
    pub compat: bool,
    /// Run every N-th input from I (a job array's index I of N jobs, from 0)
    #[arg(long, value_name = "I/N", default_value = "0/1")]
    pub shard: tad_base::Shard,
    /// Write the scored episodes to DIR/results.json (DIR/results.I-of-N.json with
    /// --shard), for `tadslc merge`
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Exit with status 1 when an episode meets one of these: `collision`, `red_light`,
    /// `stop_sign`, `lane_invasion`, `off_road` (comma-separated or repeated)
    #[arg(long, value_name = "CRITERIA", value_delimiter = ',', value_parser = parse_criterion)]
    pub fail_on: Vec<EventKind>,
    /// Write a JUnit XML report: a test suite per scenario, a test case per ego and seed,
    /// failed when it meets a `--fail-on` criterion
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
}

/// A `--fail-on` criterion: an event of the runtime's criteria.
fn parse_criterion(text: &str) -> Result<EventKind, String> {
    EventKind::parse(text).ok_or_else(|| {
        let names: Vec<&str> = EventKind::ALL.iter().map(|k| k.as_str()).collect();
        format!("`{text}` is not a criterion (the criteria are {})", names.join(", "))
    })
}

/// `A..B` (B excluded, as in Rust), `A..=B` (B included) or a single seed `A`.
pub fn parse_seeds(text: &str) -> Result<Range<u64>, String> {
    let number = |s: &str| s.trim().parse::<u64>().map_err(|_| format!("`{s}` is not a seed (a whole number)"));
    let range = match text.split_once("..") {
        Some((a, b)) => match b.strip_prefix('=') {
            Some(last) => number(a)?..number(last)?.saturating_add(1),
            None => number(a)?..number(b)?,
        },
        None => {
            let a = number(text)?;
            a..a.saturating_add(1)
        }
    };
    if range.is_empty() {
        return Err(format!("`{text}` holds no seed: give A..B with A < B (B excluded)"));
    }
    Ok(range)
}

/// `--render`'s path: a picture whose extension names its format, or a directory.
fn picture_path(path: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(path);
    if tad_render::Format::of(&path).is_some() || path.is_dir() || path.extension().is_none() {
        return Ok(path);
    }
    Err("the picture's extension names its format: .svg, .png or .gif (or give a directory, for one \
         SVG per scenario, ego and seed)"
        .into())
}

/// Where `--render` draws: one picture of the first episode, or every episode into a
/// directory.
enum Render<'a> {
    File(&'a std::path::Path, tad_render::Format),
    Dir(&'a std::path::Path),
}

impl Render<'_> {
    fn of(path: &std::path::Path) -> Render<'_> {
        match tad_render::Format::of(path) {
            Some(format) if !path.is_dir() => Render::File(path, format),
            _ => Render::Dir(path),
        }
    }
}

/// A name made safe for a file: letters, digits, `-`, `_` and `.` kept, the rest `_`.
fn file_part(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || "-_.".contains(c) { c } else { '_' }).collect()
}

/// An episode's figure in `--render DIR`: DIR/SCENARIO.EGO.seedN.svg.
fn render_into(
    dir: &std::path::Path,
    loaded: &crate::scenes::Loaded,
    ego: &str,
    played: &Played,
) -> Result<(), String> {
    let seed = played.episode.seed.unwrap_or(0);
    let name = format!("{}.{}.seed{seed}.svg", file_part(&loaded.scene.name), file_part(ego));
    let path = dir.join(name);
    let picture = record::picture(&loaded.scene, ego, &played.episode, tad_render::Format::Svg);
    std::fs::write(&path, picture).map_err(|e| format!("cannot write `{}`: {e}", path.display()))
}

pub fn run(args: &RunArgs, color: bool) -> Result<Status, CliError> {
    let mut policies = Vec::new();
    // comma-separated or repeated; an `external:CMD` keeps its commas
    let egos: Vec<String> = args.egos.iter().flat_map(|list| tad_policy::split_specs(list)).collect();
    for spec in &egos {
        policies.push(tad_policy::parse_policy(spec).map_err(|e| CliError::usage(format!("--ego {spec}: {e}")))?);
    }
    // raised by inputs that do not load, and by output that cannot be written
    let (scenes, mut status) = crate::scenes::load_shard(&args.paths, args.shard, color)?;
    if scenes.is_empty() {
        return Err(CliError::usage("nothing to run"));
    }
    let mode = if args.compat { Mode::Compat } else { Mode::Fixed };
    let keep_frames = args.trace.is_some() || args.render.is_some();
    let opts = Options { mode, keep_frames, ..Options::default() };
    let total = scenes.len() * policies.len() * (args.seeds.end - args.seeds.start) as usize;
    let progress = crate::output::progress(total, "episodes");
    let mut trace = match &args.trace {
        Some(path) => Some(std::io::BufWriter::new(
            std::fs::File::create(path)
                .map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?,
        )),
        None => None,
    };
    let render = args.render.as_deref().map(Render::of);
    if let Some(Render::Dir(dir)) = &render {
        std::fs::create_dir_all(dir)
            .map_err(|e| CliError::usage(format!("cannot make the directory `{}`: {e}", dir.display())))?;
    }
    let mut rendered = 0usize;
    let mut done: Vec<Played> = Vec::new();
    for (f, loaded) in scenes.iter().enumerate() {
        for (e, policy) in policies.iter_mut().enumerate() {
            for seed in args.seeds.clone() {
                let params = tad_runtime::sample::sample(&loaded.scene.program.params, Some(seed));
                let episode = tad_runtime::run(&loaded.scene, Some(seed), params, policy.as_mut(), &opts);
                if let Some(why) = &episode.failure {
                    // the run goes on with the next episode
                    status = Status::Usage;
                    errln!("error: {}: ego {}, seed {seed}: {why}", loaded.name, policy.name())?;
                }
                let Ok(score) = tad_metrics::score_episode(&episode.records, mode) else { continue };
                if let Some(w) = trace.as_mut()
                    && let Err(err) = record::write_trace(w, &loaded.name, policy.name(), &loaded.scene, &episode)
                {
                    return Err(CliError::usage(format!("cannot write the trace: {err}")));
                }
                if args.format == RunFormat::Json {
                    outln!("{}", record::episode_json(&loaded.name, policy.name(), &episode, &score))?;
                }
                let mut played = Played { scenario: f, ego: e, episode, score };
                if let Some(Render::Dir(dir)) = &render {
                    match render_into(dir, loaded, policy.name(), &played) {
                        Ok(()) => rendered += 1,
                        Err(err) => {
                            status = Status::Usage;
                            errln!("error: {err}")?;
                        }
                    }
                }
                if !matches!(render, Some(Render::File(..))) || !done.is_empty() {
                    played.episode.frames = Vec::new();
                }
                done.push(played);
                progress.inc(1);
            }
        }
    }
    progress.finish_and_clear();
    if let Some(w) = trace.as_mut()
        && let Err(e) = w.flush()
    {
        status = Status::Usage;
        errln!("error: cannot write the trace: {e}")?;
    }
    let names: Vec<String> = policies.iter().map(|p| p.name().to_string()).collect();
    if let Some(dir) = &args.out {
        // named as the table names them, so that `merge` prints the same table
        let scenarios: Vec<&str> = scenes.iter().map(|s| s.scene.name.as_str()).collect();
        if let Err(e) = record::results(&scenarios, &names, args.seeds.clone(), args.shard, &done, mode).write(dir) {
            status = Status::Usage;
            errln!("error: cannot write the results to `{}`: {e}", dir.display())?;
        }
    }
    match args.format {
        RunFormat::Json => {
            for (e, name) in names.iter().enumerate() {
                let scores: Vec<_> = done.iter().filter(|d| d.ego == e).map(|d| d.score.clone()).collect();
                if let Some(value) = record::aggregate_json(name, &scores, mode) {
                    outln!("{value}")?;
                }
            }
        }
        RunFormat::Table => {
            let scenarios: Vec<&str> = scenes.iter().map(|s| s.scene.name.as_str()).collect();
            out!("{}", record::table(&scenarios, &names, &done, mode))?;
        }
    }
    status = status.max(gate(args, &scenes, &names, &done)?);
    if let Some(Render::Dir(dir)) = &render {
        errln!("rendered {} to `{}`", crate::plural(rendered, "episode"), dir.display())?;
    }
    if let (Some(Render::File(path, format)), Some(first)) = (render, done.first()) {
        let loaded = &scenes[first.scenario];
        if let Err(e) = std::fs::write(path, record::picture(&loaded.scene, &names[first.ego], &first.episode, format))
        {
            status = Status::Usage;
            errln!("error: cannot write `{}`: {e}", path.display())?;
        } else {
            errln!(
                "{}: rendered seed {} with {} to `{}`",
                loaded.name,
                first.episode.seed.unwrap_or(0),
                names[first.ego],
                path.display()
            )?;
        }
    }
    Ok(status)
}

/// The CI gate: the JUnit report, and status 1 when an episode met a `--fail-on` criterion
/// (how many, by criterion, on standard error).
fn gate(
    args: &RunArgs,
    scenes: &[crate::scenes::Loaded],
    egos: &[String],
    done: &[Played],
) -> Result<Status, CliError> {
    if let Some(path) = &args.junit {
        let suites: Vec<(&str, f64)> = scenes.iter().map(|s| (s.name.as_str(), s.scene.limits.dt)).collect();
        let xml = record::junit(&suites, egos, done, &args.fail_on);
        std::fs::write(path, xml).map_err(|e| CliError::usage(format!("cannot write `{}`: {e}", path.display())))?;
    }
    let mut met: Vec<(&str, usize)> = Vec::new();
    for event in done.iter().filter_map(|p| record::failed(&p.episode, &args.fail_on)) {
        match met.iter_mut().find(|(k, _)| *k == event.kind.as_str()) {
            Some((_, n)) => *n += 1,
            None => met.push((event.kind.as_str(), 1)),
        }
    }
    if met.is_empty() {
        return Ok(Status::Ok);
    }
    let failing: usize = met.iter().map(|(_, n)| n).sum();
    let by: Vec<String> = met.iter().map(|(k, n)| format!("{k} {n}")).collect();
    errln!("--fail-on: {failing} of {} episodes failed ({})", done.len(), by.join(", "))?;
    Ok(Status::Failed)
}

#[cfg(test)]
mod tests {
    use super::parse_seeds;

    #[test]
    fn seeds_are_rust_ranges() {
        assert_eq!(parse_seeds("3..6"), Ok(3..6));
        assert_eq!(parse_seeds("3..=6"), Ok(3..7));
        assert_eq!(parse_seeds("4"), Ok(4..5));
        assert!(parse_seeds("5..5").unwrap_err().contains("holds no seed"));
        assert!(parse_seeds("a..3").unwrap_err().contains("not a seed"));
    }
}
