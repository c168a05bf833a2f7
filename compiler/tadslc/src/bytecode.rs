//! `tadslc build --target bytecode` and `tadslc disasm` (`spec/output.md`, `spec/bytecode.md`).
//!
//! `build` checks each file as the Scenic target does (a file with errors is refused, its
//! errors printed, status 1), lays the scenario out, lowers the layout to a program
//! (`tad_bytecode::lower`) and writes `NAME.tadc` into the `-o` directory; the bytes are
//! binary, so an output directory is required. `disasm` loads a `.tadc` file (every byte
//! checked) and prints its listing; a file that does not load is status 1, with the
//! loader's reason and byte offset.

use std::path::{Path, PathBuf};

use crate::files::{self, Search};
use crate::output::{CliError, Closed};
use crate::{Status, err, errln, out, plural};
use tad_check::Options;
use tad_db::Database;

/// `build --target bytecode`; `scenic_options`: a Scenic-only option (`--map`,
/// `--map-dir`) was given.
pub fn build(paths: &[PathBuf], out: Option<&Path>, scenic_options: bool, color: bool) -> Status {
    crate::output::finish(build_in(paths, out, scenic_options, color))
}

fn build_in(paths: &[PathBuf], out: Option<&Path>, scenic_options: bool, color: bool) -> Result<Status, CliError> {
    if scenic_options {
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
        let Some(program) = compile(&mut db, input, "built", color)? else {
            status = status.max(Status::Failed);
            continue;
        };
        let bytes = tad_bytecode::encode(&program);
        let stem = input
            .path
            .as_deref()
            .and_then(Path::file_stem)
            .map_or_else(|| "stdin".to_string(), |s| s.to_string_lossy().into_owned());
        let target = dir.join(format!("{stem}.tadc"));
        if written.contains(&target) {
            status = status.max(Status::Usage);
            errln!("error: {} would overwrite `{}`, written for an earlier file", input.name, target.display())?;
            continue;
        }
        if let Err(e) = std::fs::write(&target, &bytes) {
            status = status.max(Status::Usage);
            errln!("error: cannot write `{}`: {e}", target.display())?;
            continue;
        }
        let actors = program.code.iter().filter(|i| matches!(i, tad_bytecode::Instr::Spawn { .. })).count();
        errln!(
            "{}: wrote {} ({}, {}, {} bytes)",
            input.name,
            target.display(),
            plural(actors, "actor"),
            plural(program.code.len(), "instruction"),
            bytes.len()
        )?;
        written.push(target);
    }
    Ok(status)
}

/// A scenario file's program: checked (errors printed, then `NAME: not VERB`), resolved,
/// laid out and lowered; `None` when it has errors or holds no scenario. What `build
/// --target bytecode` writes and `run` runs.
pub fn compile(
    db: &mut Database,
    input: &files::Input,
    verb: &str,
    color: bool,
) -> Result<Option<tad_bytecode::Program>, Closed> {
    match tad_eval::pipeline::compile(db, input) {
        Ok(program) => Ok(Some(program)),
        Err(refusal) => {
            err!("{}", refusal.render(input, verb, color))?;
            Ok(None)
        }
    }
}

/// `disasm FILE.tadc`: the listing on standard output.
pub fn disasm(path: &Path) -> Status {
    crate::output::finish(disasm_in(path))
}

fn disasm_in(path: &Path) -> Result<Status, CliError> {
    let bytes = std::fs::read(path).map_err(|e| CliError::usage(format!("cannot read `{}`: {e}", path.display())))?;
    // a file that does not load is input with errors (status 1), as under `run`
    let program = tad_bytecode::decode(&bytes).map_err(|e| CliError::failed(format!("{}: {e}", path.display())))?;
    out!("{}", tad_bytecode::disasm(&program))?;
    Ok(Status::Ok)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("tadslc-bytecode-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn builds_a_program_per_input_and_refuses_without_an_output_directory() {
        let out = scratch("ok");
        let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/safety/right_turn.tad");
        assert_eq!(build(std::slice::from_ref(&example), Some(&out), false, false), Status::Ok);
        let bytes = std::fs::read(out.join("right_turn.tadc")).unwrap();
        let program = tad_bytecode::decode(&bytes).unwrap();
        assert_eq!(program.name, "right_turn");
        assert_eq!(disasm(&out.join("right_turn.tadc")), Status::Ok);
        assert_eq!(build(std::slice::from_ref(&example), None, false, false), Status::Usage);
        assert_eq!(build(std::slice::from_ref(&example), Some(&out), true, false), Status::Usage);
        std::fs::write(out.join("bad.tadc"), b"TADC\x09\x00").unwrap();
        assert_eq!(disasm(&out.join("bad.tadc")), Status::Failed);
        assert_eq!(disasm(&out.join("missing.tadc")), Status::Usage);
    }
}
