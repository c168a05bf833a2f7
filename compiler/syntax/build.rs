//! Generates the parser from `src/grammar.lalrpop` (LALRPOP) into `OUT_DIR`.

fn main() {
    let out = std::env::var("OUT_DIR").expect("cargo sets OUT_DIR");
    lalrpop::Configuration::new()
        .emit_rerun_directives(true)
        .set_out_dir(out)
        .process_file("src/grammar.lalrpop")
        .expect("src/grammar.lalrpop should build");
}
