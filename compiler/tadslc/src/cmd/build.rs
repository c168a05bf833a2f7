//! `tadslc build`: a Scenic 3 program per scenario (`--target scenic`), a bytecode
//! program for the runtime (`--target bytecode`, `spec/bytecode.md`), or OpenSCENARIO on a
//! generated OpenDRIVE road or, with `--map`, a CARLA town (`--target openscenario`,
//! `spec/backends/openscenario.md`).
//!
//! Each file is checked first: a file with errors is refused (its errors are printed and
//! the status is 1); the others are resolved (`tad_db::resolve`, the typed IR) and emitted
//! by `tad-scenic`, whose warnings (W07xx) are printed. One file without `-o` goes to standard output; otherwise `NAME.scenic` is
//! written into the `-o` directory. A map file that is not where a program will load it
//! from (`--map-dir`, or beside the program) is a warning, once per map
//! (`spec/output.md`). The bytecode target checks each file the same way, lays the
//! scenario out and lowers it (`tad_eval::pipeline`), and writes `NAME.tadc` into the `-o`
//! directory, which it requires; the openscenario target resolves each file the same way
//! (`tad_eval::pipeline::resolved`) and writes its two or three files there.

use std::path::{Path, PathBuf};

use crate::files::{self, Search};
use crate::output::{CliError, Closed};
use crate::{Status, err, errln, out, plural};
use tad_check::Options;
use tad_db::Database;
use tad_diagnostics::render::{FileReport, human};
use tad_scenic::{EmitOptions, Simulator};

/// `tadslc build`'s arguments.
#[derive(clap::Args)]
pub struct BuildArgs {
    /// Scenario files or directories (searched recursively for *.tad)
    #[arg(required = true)]
    pub paths: Vec<PathBuf>,
    /// The target language
    #[arg(long, value_enum, default_value_t = Target::Scenic)]
    pub target: Target,
    /// Output directory (default: standard output for a single file; required for
    /// bytecode)
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Directory of the CARLA OpenDRIVE maps (`TownNN.xodr`); default: the map
    /// next to the program (or, for openscenario, in the output directory)
    #[arg(long)]
    pub map_dir: Option<PathBuf>,
    /// The town to use, e.g. `Town10HD` (scenic default: the first map with the road's
    /// features; openscenario default: a road generated from the layout)
    #[arg(long, value_parser = |s: &str| tad_scenic::maps::town(s).map(String::from))]
    pub map: Option<String>,
    /// Which simulator the behaviors are written for
    #[arg(long, value_enum, default_value_t = SimulatorArg::Carla)]
    pub simulator: SimulatorArg,
}

/// The targets of `build`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Target {
    /// Scenic 3 programs (`NAME.scenic`)
    Scenic,
    /// Bytecode for the runtime (`NAME.tadc`, `spec/bytecode.md`)
    Bytecode,
    /// OpenSCENARIO XML 1.2 on a generated OpenDRIVE 1.7 road (`NAME.xosc`, `NAME.xodr`,
    /// `NAME.distribution.xosc`), or with `--map` on a CARLA town
    /// (`spec/backends/openscenario.md`)
    Openscenario,
}

/// `--simulator`: `tad_scenic::Simulator` on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SimulatorArg {
    Carla,
    Newtonian,
}

impl From<SimulatorArg> for Simulator {
    fn from(simulator: SimulatorArg) -> Simulator {
        match simulator {
            SimulatorArg::Carla => Simulator::Carla,
            SimulatorArg::Newtonian => Simulator::Newtonian,
        }
    }
}

/// `tadslc build`, for either target.
pub fn run(args: &BuildArgs, color: bool) -> Result<Status, CliError> {
    match args.target {
        Target::Scenic => scenic(args, color),
        Target::Bytecode => bytecode(args, color),
        Target::Openscenario => openscenario(args, color),
    }
}

/// Where a program written to `out` (a directory, or standard output) will look for its
/// map, when that file is not there: the programs that load it, in words, and the file.
struct MissingMap {
    file: PathBuf,
    programs: Vec<String>,
}

/// `--target scenic`: a Scenic program per scenario.
fn scenic(args: &BuildArgs, color: bool) -> Result<Status, CliError> {
    let (paths, out, map_dir, map) =
        (&args.paths, args.output.as_deref(), args.map_dir.as_deref(), args.map.as_deref());
    let simulator = Simulator::from(args.simulator);
    // raised by files with errors and outputs that cannot be written; the others still build
    let mut status = Status::Ok;
    let (inputs, read) = files::load(paths, Search::Tad)?;
    status = status.max(read);
    if out.is_none() && inputs.len() > 1 {
        return Err(CliError::usage(format!(
            "{} to build: give an output directory with -o",
            plural(inputs.len(), "file")
        )));
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(dir).map_err(|e| CliError::usage(format!("cannot create `{}`: {e}", dir.display())))?;
    }
    // The program names its map by path: make a relative map directory absolute, so the
    // program finds it wherever it is written.
    let map_dir = map_dir.map(|d| std::path::absolute(d).unwrap_or_else(|_| d.to_path_buf()));
    let mut written: Vec<PathBuf> = Vec::new();
    let mut missing: Vec<MissingMap> = Vec::new();
    let mut to_stdout: Option<(String, String)> = None;
    let mut db = Database::new(Options::default());
    for input in &inputs {
        let checked = tad_db::host::diagnose_in(&mut db, input);
        if checked.diagnostics.iter().any(|d| d.is_error()) {
            status = status.max(Status::Failed);
            let errors: Vec<_> = checked.diagnostics.iter().filter(|d| d.is_error()).cloned().collect();
            let report = FileReport::new(&input.name, &input.text, &errors);
            err!("{}", human::render(&report, color))?;
            errln!("{}: not built: it has errors", input.name)?;
            continue;
        }
        let file = tad_db::host::register(&mut db, input);
        let module = &tad_db::analyze(&db, file).module;
        let scenario = tad_db::resolve(&db, file);
        let options = EmitOptions {
            simulator,
            map: map.map(str::to_string),
            map_dir: map_dir.as_ref().map(|d| d.to_string_lossy().into_owned()),
            source: Some(input.name.clone()),
        };
        let emitted = tad_scenic::build(module, scenario.as_ref(), &options);
        let report = FileReport::new(&input.name, &input.text, &emitted.diagnostics);
        err!("{}", human::render(&report, color))?;
        if emitted.diagnostics.iter().any(|d| d.is_error()) {
            status = status.max(Status::Failed);
            errln!("{}: not built", input.name)?;
            continue;
        }
        let map_file = format!("{}.xodr", emitted.map);
        let warnings = emitted.diagnostics.len();
        match out {
            None => {
                match &map_dir {
                    Some(dir) => note_missing(&mut missing, dir.join(&map_file), &input.name),
                    // `localPath`: beside the program, wherever it is saved
                    None => to_stdout = Some((input.name.clone(), map_file)),
                }
                out!("{}", emitted.text)?;
            }
            Some(dir) => {
                let Some(target) = write_into(dir, input, "scenic", emitted.text.as_bytes(), &mut written)? else {
                    status = status.max(Status::Usage);
                    continue;
                };
                errln!(
                    "{}: wrote `{}` ({}, {}, {})",
                    input.name,
                    target.display(),
                    emitted.map,
                    simulator.as_str(),
                    match warnings {
                        0 => "no warnings".to_string(),
                        n => plural(n, "warning"),
                    }
                )?;
                let map_file = map_dir.as_deref().unwrap_or(dir).join(&map_file);
                note_missing(&mut missing, map_file, &target.display().to_string());
            }
        }
    }
    report_missing_maps(&missing, map_dir.is_some())?;
    if let Some((name, map_file)) = to_stdout {
        errln!(
            "{name}: note: the program loads `{map_file}` from the directory it is saved in (`localPath`); \
             save it beside the CARLA maps, or build with `--map-dir DIR`, DIR the directory of the CARLA maps"
        )?;
    }
    Ok(status)
}

/// `--target bytecode`: `NAME.tadc` per scenario into the `-o` directory (the bytes are
/// binary: an output directory is required).
fn bytecode(args: &BuildArgs, color: bool) -> Result<Status, CliError> {
    let (paths, out) = (&args.paths, args.output.as_deref());
    if args.map_dir.is_some() || args.map.is_some() {
        return Err(CliError::usage("`--map` and `--map-dir` are options of the scenic target"));
    }
    let dir = out
        .ok_or_else(|| CliError::usage("the bytecode target writes binary files: give an output directory with -o"))?;
    // raised by files with errors and outputs that cannot be written; the others still build
    let mut status = Status::Ok;
    let (inputs, read) = files::load(paths, Search::Tad)?;
    status = status.max(read);
    std::fs::create_dir_all(dir).map_err(|e| CliError::usage(format!("cannot create `{}`: {e}", dir.display())))?;
    let mut written: Vec<PathBuf> = Vec::new();
    let mut db = Database::new(Options::default());
    for input in &inputs {
        let Some(program) = crate::scenes::compile(&mut db, input, "built", color)? else {
            status = status.max(Status::Failed);
            continue;
        };
        let bytes = tad_bytecode::encode(&program);
        let Some(target) = write_into(dir, input, "tadc", &bytes, &mut written)? else {
            status = status.max(Status::Usage);
            continue;
        };
        let actors = program.code.iter().filter(|i| matches!(i, tad_bytecode::Instr::Spawn { .. })).count();
        errln!(
            "{}: wrote `{}` ({}, {}, {} bytes)",
            input.name,
            target.display(),
            plural(actors, "actor"),
            plural(program.code.len(), "instruction"),
            bytes.len()
        )?;
    }
    Ok(status)
}

/// `--target openscenario`: `NAME.xosc`, `NAME.xodr` and (with parameters)
/// `NAME.distribution.xosc` per scenario into the `-o` directory, which it requires.
fn openscenario(args: &BuildArgs, color: bool) -> Result<Status, CliError> {
    let dir = args.output.as_deref().ok_or_else(|| {
        CliError::usage(
            "the openscenario target writes two or three files per scenario: give an output directory with -o",
        )
    })?;
    let town = match &args.map {
        Some(name) => Some(read_town(name, args.map_dir.as_deref(), dir)?),
        None if args.map_dir.is_some() => {
            return Err(CliError::usage(
                "`--map-dir` goes with `--map TownNN`: the openscenario target generates its road otherwise",
            ));
        }
        None => None,
    };
    let mut status = Status::Ok;
    let (inputs, read) = files::load(&args.paths, Search::Tad)?;
    status = status.max(read);
    std::fs::create_dir_all(dir).map_err(|e| CliError::usage(format!("cannot create `{}`: {e}", dir.display())))?;
    let mut written: Vec<PathBuf> = Vec::new();
    let mut db = Database::new(Options::default());
    for input in &inputs {
        let scenario = match tad_eval::pipeline::resolved_warned(&mut db, input) {
            Ok((scenario, warnings)) => {
                crate::scenes::warn_scene(input, warnings, color)?;
                scenario
            }
            Err(refusal) => {
                err!("{}", refusal.render(input, "built", color))?;
                status = status.max(Status::Failed);
                continue;
            }
        };
        let options = tad_openscenario::EmitOptions { stem: stem(input), source: input.name.clone() };
        let emitted = match &town {
            Some((town, file)) => match tad_openscenario::emit_on_town(&scenario, &options, town, file) {
                Ok(emitted) => emitted,
                Err(why) => {
                    errln!("error: {}: not built: {why}", input.name)?;
                    status = status.max(Status::Failed);
                    continue;
                }
            },
            None => tad_openscenario::emit(&scenario, &options),
        };
        err!("{}", human::render(&FileReport::new(&input.name, &input.text, &emitted.diagnostics), color))?;
        let mut names = Vec::new();
        for (ext, text) in emitted.files() {
            match write_into(dir, input, ext, text.as_bytes(), &mut written)? {
                Some(target) => names.push(target.display().to_string()),
                None => status = status.max(Status::Usage),
            }
        }
        let warnings = match emitted.diagnostics.len() {
            0 => "no warnings".to_string(),
            n => plural(n, "warning"),
        };
        errln!("{}: wrote {} ({warnings})", input.name, names.join(", "))?;
    }
    Ok(status)
}

/// `--map TOWN` of the openscenario target: the town's OpenDRIVE file read from `--map-dir`
/// (else the output directory, where the scenario then names it beside itself), and the path
/// the scenario names it by.
fn read_town(
    name: &str,
    map_dir: Option<&Path>,
    out: &Path,
) -> Result<(tad_openscenario::town::Town, String), CliError> {
    let file = format!("{name}.xodr");
    let (path, named) = match map_dir {
        Some(d) => {
            let path = d.join(&file);
            let path = std::fs::canonicalize(&path).or_else(|_| std::path::absolute(&path)).unwrap_or(path);
            let named = path.to_string_lossy().into_owned();
            (path, named)
        }
        None => (out.join(&file), file.clone()),
    };
    let text = std::fs::read_to_string(&path).map_err(|e| {
        let hint = if map_dir.is_none() { ": give the directory of the CARLA maps with `--map-dir DIR`" } else { "" };
        CliError::usage(format!("cannot read `{}` ({e}){hint}", path.display()))
    })?;
    let town = tad_openscenario::town::Town::parse(name, &text)
        .map_err(|e| CliError::usage(format!("`{}`: {e}", path.display())))?;
    Ok((town, named))
}

/// The stem of an input's outputs: its file's (`stdin` without a path).
fn stem(input: &files::Input) -> String {
    input
        .path
        .as_deref()
        .and_then(Path::file_stem)
        .map_or_else(|| "stdin".to_string(), |s| s.to_string_lossy().into_owned())
}

/// Writes `bytes` for `input` as `DIR/STEM.EXT` (`stdin` without a path) and adds it to
/// `written`; `None` when it would overwrite what an earlier input wrote or cannot be
/// written (said on standard error; the caller's status is 2).
fn write_into(
    dir: &Path,
    input: &files::Input,
    ext: &str,
    bytes: &[u8],
    written: &mut Vec<PathBuf>,
) -> Result<Option<PathBuf>, Closed> {
    let target = dir.join(format!("{}.{ext}", stem(input)));
    if written.contains(&target) {
        errln!("error: {} would overwrite `{}`, written for an earlier file", input.name, target.display())?;
        return Ok(None);
    }
    if let Err(e) = std::fs::write(&target, bytes) {
        errln!("error: cannot write `{}`: {e}", target.display())?;
        return Ok(None);
    }
    written.push(target.clone());
    Ok(Some(target))
}

/// Remember that `program` loads `file`, if `file` does not exist.
fn note_missing(missing: &mut Vec<MissingMap>, file: PathBuf, program: &str) {
    if file.is_file() {
        return;
    }
    match missing.iter_mut().find(|m| m.file == file) {
        Some(known) => known.programs.push(program.to_string()),
        None => missing.push(MissingMap { file, programs: vec![program.to_string()] }),
    }
}

/// One warning per map file that a program loads and that does not exist.
fn report_missing_maps(missing: &[MissingMap], map_dir_given: bool) -> Result<(), Closed> {
    for m in missing {
        let others = match m.programs.len() {
            1 => String::new(),
            n => format!(" (so do {})", plural(n - 1, "other program")),
        };
        errln!("{}: warning: the program loads `{}`, which does not exist{others}", m.programs[0], m.file.display())?;
        let dir = m.file.parent().map_or_else(String::new, |d| d.display().to_string());
        let name = m.file.file_name().map_or_else(String::new, |f| f.to_string_lossy().into_owned());
        if map_dir_given {
            errln!(
                "  = help: give `--map-dir` the directory of the CARLA maps (`TownNN.xodr`), or put `{name}` in `{dir}`"
            )?;
        } else {
            errln!(
                "  = help: build with `--map-dir DIR`, DIR the directory of the CARLA maps (`TownNN.xodr`), or put `{name}` in `{dir}`"
            )?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::finish;

    /// A fresh directory under the system's temporary one, removed when the test ends
    /// (passed or not).
    struct Scratch(PathBuf);

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    impl std::ops::Deref for Scratch {
        type Target = Path;
        fn deref(&self) -> &Path {
            &self.0
        }
    }

    fn scratch(name: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("tadslc-build-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    fn build(paths: &[PathBuf], output: Option<&Path>, map_dir: Option<&str>, simulator: SimulatorArg) -> BuildArgs {
        BuildArgs {
            paths: paths.to_vec(),
            target: Target::Scenic,
            output: output.map(Path::to_path_buf),
            map_dir: map_dir.map(PathBuf::from),
            map: None,
            simulator,
        }
    }

    fn example(path: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
    }

    #[test]
    fn builds_a_scenic_file_per_input() {
        let out = scratch("ok");
        let inputs =
            [example("examples/safety/right_turn.tad"), example("examples/regions/yosemite_deer_on_curve.tad")];
        let args = build(&inputs, Some(&*out), Some("maps"), SimulatorArg::Newtonian);
        let status = finish(run(&args, false));
        assert_eq!(status, Status::Ok);
        let text = std::fs::read_to_string(out.join("right_turn.scenic")).unwrap();
        assert!(text.contains("model scenic.simulators.newtonian.driving_model"));
        let maps = std::path::absolute("maps").unwrap().join("Town10HD.xodr");
        assert!(text.contains(&format!("param map = '{}'", maps.display())), "{text}");
        assert!(out.join("yosemite_deer_on_curve.scenic").is_file());
    }

    #[test]
    fn refuses_files_with_errors_and_bad_options() {
        let dir = scratch("errors");
        let bad = dir.join("bad.tad");
        std::fs::write(&bad, "scenario bad {\n  environment {\n    weather: sunnyy\n  }\n}\n").unwrap();
        assert_eq!(
            finish(run(&build(std::slice::from_ref(&bad), Some(&*dir), None, SimulatorArg::Carla), false)),
            Status::Failed
        );
        assert!(!dir.join("bad.scenic").exists());
        let good = example("examples/safety/right_turn.tad");
        assert_eq!(finish(run(&build(&[good.clone(), good], None, None, SimulatorArg::Carla), false)), Status::Usage);
    }

    #[test]
    fn builds_a_program_per_input_and_refuses_without_an_output_directory() {
        let out = scratch("bytecode");
        let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/safety/right_turn.tad");
        let bytecode = |output: Option<&Path>, map_dir: Option<&str>| {
            let args = BuildArgs {
                target: Target::Bytecode,
                ..build(std::slice::from_ref(&example), output, map_dir, SimulatorArg::Carla)
            };
            finish(run(&args, false))
        };
        let disasm = |path: PathBuf| finish(crate::cmd::disasm::run(&crate::cmd::disasm::Args { path }));
        assert_eq!(bytecode(Some(&*out), None), Status::Ok);
        let bytes = std::fs::read(out.join("right_turn.tadc")).unwrap();
        let program = tad_bytecode::decode(&bytes).unwrap();
        assert_eq!(program.name, "right_turn");
        assert_eq!(disasm(out.join("right_turn.tadc")), Status::Ok);
        assert_eq!(bytecode(None, None), Status::Usage);
        assert_eq!(bytecode(Some(&*out), Some("maps")), Status::Usage);
        std::fs::write(out.join("bad.tadc"), b"TADC\x09\x00").unwrap();
        assert_eq!(disasm(out.join("bad.tadc")), Status::Failed);
        assert_eq!(disasm(out.join("missing.tadc")), Status::Usage);
    }
}
