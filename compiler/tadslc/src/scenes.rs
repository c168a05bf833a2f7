//! Inputs as programs and scenes, for `build --target bytecode`, `run`, `search` and
//! `train-ego`: a scenario file is compiled through `tad_eval::pipeline` (its errors
//! printed, then `NAME: not VERB`), a `.tadc` file loaded (every byte checked). An input
//! that does not load is reported and skipped: a file with errors or a corrupt `.tadc` is
//! status 1, a file that cannot be read status 2; the others still run.

use std::path::PathBuf;

use crate::files::{self, Search};
use crate::output::Closed;
use crate::{Status, err, errln};
use tad_check::Options as CheckOptions;
use tad_db::Database;
use tad_runtime::Scene;

/// A scenario file's program: checked (errors printed, then `NAME: not VERB`), resolved,
/// laid out and lowered; `None` when it has errors or holds no scenario. What `build
/// --target bytecode` writes and `run` runs.
pub fn compile(
    db: &mut Database,
    input: &files::Input,
    verb: &str,
    color: bool,
) -> Result<Option<tad_bytecode::Program>, Closed> {
    match tad_eval::pipeline::resolved_warned(db, input) {
        Ok((scenario, mut warnings)) => {
            warnings.extend(tad_eval::pipeline::runtime_notes(&scenario));
            warn_scene(input, warnings, color)?;
            Ok(Some(tad_eval::pipeline::program(&scenario, &input.name)))
        }
        Err(refusal) => {
            err!("{}", refusal.render(input, verb, color))?;
            Ok(None)
        }
    }
}

/// An input's warnings that its scene differs from the file (and, where the runtime runs
/// it, the runtime's notes), on standard error.
pub fn warn_scene(
    input: &files::Input,
    mut warnings: Vec<tad_diagnostics::Diagnostic>,
    color: bool,
) -> Result<(), Closed> {
    use tad_diagnostics::render::{FileReport, human};
    tad_diagnostics::sort(&mut warnings);
    if !warnings.is_empty() {
        err!("{}", human::render(&FileReport::new(&input.name, &input.text, &warnings), color))?;
    }
    Ok(())
}

/// One scenario ready to run, named for people.
pub struct Loaded {
    pub name: String,
    pub scene: Scene,
    /// The source it was compiled from (`None` for a `.tadc` file).
    pub source: Option<files::Input>,
    /// Its behaviour, the key of the fine-tuning split (`None` for a `.tadc` file).
    pub key: Option<String>,
}

/// Every input as a scene (sources compiled, `.tadc` files loaded), and the status
/// loading them reached: an input that does not load is reported and skipped.
pub fn load(paths: &[PathBuf], color: bool) -> Result<(Vec<Loaded>, Status), Closed> {
    let (bytecode, sources): (Vec<PathBuf>, Vec<PathBuf>) =
        paths.iter().cloned().partition(|p| p.extension().is_some_and(|e| e == "tadc"));
    let mut loaded = Vec::new();
    let mut status = Status::Ok;
    let mut db = Database::new(CheckOptions::default());
    if !sources.is_empty() {
        let (inputs, read) = files::load(&sources, Search::Scenarios)?;
        status = status.max(read);
        for input in inputs {
            let Some(program) = compile(&mut db, &input, "run", color)? else {
                status = status.max(Status::Failed);
                continue;
            };
            let file = tad_db::host::register(&mut db, &input);
            let key = tad_eval::corpus::behaviour_of(&db, file);
            match Scene::new(&program) {
                Ok(scene) => {
                    loaded.push(Loaded { name: input.name.clone(), scene, source: Some(input.clone()), key: Some(key) })
                }
                Err(e) => {
                    status = status.max(Status::Failed);
                    errln!("{}: not run: {e}", input.name)?;
                }
            }
        }
    }
    for path in bytecode {
        let name = path.display().to_string();
        // a file that cannot be read is an I/O failure (2); one that does not load is
        // input with errors (1), as under `disasm`
        let program = match std::fs::read(&path) {
            Ok(bytes) => tad_bytecode::decode(&bytes).map_err(|e| (Status::Failed, e.to_string())),
            Err(e) => Err((Status::Usage, format!("cannot read it: {e}"))),
        };
        match program.and_then(|p| Scene::new(&p).map_err(|e| (Status::Failed, e.to_string()))) {
            Ok(scene) => loaded.push(Loaded { name, scene, source: None, key: None }),
            Err((failed, e)) => {
                status = status.max(failed);
                errln!("error: {name}: {e}")?;
            }
        }
    }
    Ok((loaded, status))
}

/// The inputs of one shard (every N-th loaded scenario from I), and the loading's status.
pub fn load_shard(paths: &[PathBuf], shard: tad_base::Shard, color: bool) -> Result<(Vec<Loaded>, Status), Closed> {
    let (loaded, status) = load(paths, color)?;
    Ok((loaded.into_iter().enumerate().filter(|(k, _)| shard.takes(*k)).map(|(_, l)| l).collect(), status))
}
