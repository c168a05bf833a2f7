//! The Helix package: its queries are the tree-sitter grammar's, with Helix's names for the
//! captures it names differently, and its configuration starts `tadslc lsp`.

/// nvim-treesitter capture → Helix capture, where they differ.
const RENAMES: &[(&str, &str)] = &[
    ("@string.escape", "@constant.character.escape"),
    ("@number", "@constant.numeric"),
    ("@property", "@variable.other.member"),
    ("@module", "@namespace"),
];

#[test]
fn the_highlight_queries_are_the_grammars_renamed() {
    let dir = tad_editors::dir();
    let mut expected = std::fs::read_to_string(dir.join("tree-sitter-tad/queries/highlights.scm")).unwrap();
    for (from, to) in RENAMES {
        expected = expected.replace(from, to);
    }
    let helix = std::fs::read_to_string(dir.join("helix/queries/tad/highlights.scm")).unwrap();
    let body: String = helix.lines().skip_while(|l| l.starts_with(";;")).collect::<Vec<_>>().join("\n");
    assert_eq!(body.trim(), expected.trim(), "regenerate editors/helix/queries/tad/highlights.scm from the grammar's");
}

#[test]
fn the_configuration_starts_the_server() {
    let config = std::fs::read_to_string(tad_editors::dir().join("helix/languages.toml")).unwrap();
    assert!(config.contains("command = \"tadslc\"") && config.contains("args = [\"lsp\"]"));
    assert!(config.contains("file-types = [\"tad\"]"));
}
