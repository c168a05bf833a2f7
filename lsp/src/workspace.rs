//! The server's state: the open documents and the database they are set in.
//!
//! A document is the editor's text of a file, which wins over the disk: a `use` of a
//! module open in the editor reads its unsaved text ([`Overlay`]), and closing it puts the
//! disk's text back. Documents without a file path (`untitled:`) get a virtual path, so
//! they are still checked. The embedded standard library is written once to a read-only
//! folder so a client can open it (go to definition into `core.tad`); opening one of those
//! files maps back to the embedded module, never a second copy of its declarations.
//!
//! Edits are applied here, synchronously, by the notification handlers (style.md §9): the
//! database is only ever written under the state's lock, and every reader works on a
//! clone, which salsa cancels when a write comes.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use tad_check::Options;
use tad_db::{Database, FileSystem, Language, RealFs, SourceFile};
use tower_lsp_server::ls_types::{TextDocumentContentChangeEvent, Uri};

use crate::convert::Locator;
use crate::line_index::{Encoding, LineIndex};

/// One open document.
#[derive(Clone, Debug)]
pub struct Document {
    pub uri: Uri,
    pub version: i32,
    /// Shared with readers; an edit copies it only while one still holds it.
    pub text: Arc<String>,
    pub index: Arc<LineIndex>,
    pub file: SourceFile,
    /// A file of the embedded standard library: never edited, never diagnosed.
    pub read_only: bool,
}

pub struct Workspace {
    pub db: Database,
    pub docs: HashMap<Uri, Document>,
    pub options: Options,
    pub encoding: Encoding,
    stdlib_dir: Option<PathBuf>,
}

/// The open documents' texts over the disk.
struct Overlay<'a>(&'a HashMap<PathBuf, String>);

impl FileSystem for Overlay<'_> {
    fn read(&self, path: &Path) -> Option<String> {
        self.0.get(path).cloned().or_else(|| RealFs.read(path))
    }
}

impl Workspace {
    pub fn new(options: Options) -> Self {
        Workspace {
            db: Database::new(options.clone()),
            docs: HashMap::new(),
            options,
            encoding: Encoding::Utf16,
            stdlib_dir: write_stdlib(),
        }
    }

    /// A copy of the database for a reader (cheap: salsa shares the storage).
    pub fn snapshot(&self) -> Database {
        self.db.clone()
    }

    pub fn open(&mut self, uri: Uri, language_id: &str, version: i32, text: String) -> &Document {
        let path = path_of(&uri);
        if let Some(file) = self.standard_file(&path) {
            let index = Arc::new(LineIndex::new(file.text(&self.db)));
            let text = Arc::new(file.text(&self.db).clone());
            let doc = Document { uri: uri.clone(), version, text, index, file, read_only: true };
            return self.docs.entry(uri).insert_entry(doc).into_mut();
        }
        let language = match language_id {
            "tad" => Language::Tad,
            "yaml" => Language::Yaml,
            _ => Language::guess(&path, &text),
        };
        let file = self.set(&path, &text, language);
        let doc = Document {
            uri: uri.clone(),
            version,
            index: Arc::new(LineIndex::new(&text)),
            text: Arc::new(text),
            file,
            read_only: false,
        };
        self.docs.entry(uri).insert_entry(doc).into_mut()
    }

    /// Apply a `didChange`'s edits in order; `None` for a document not open.
    pub fn change(
        &mut self,
        uri: &Uri,
        version: i32,
        changes: Vec<TextDocumentContentChangeEvent>,
    ) -> Option<&Document> {
        let encoding = self.encoding;
        let (text, language) = {
            let doc = self.docs.get_mut(uri)?;
            if doc.read_only {
                return self.docs.get(uri);
            }
            for change in changes {
                match change.range {
                    Some(range) => {
                        let span = doc.index.span(&doc.text, range, encoding);
                        Arc::make_mut(&mut doc.text).replace_range(span.start..span.end, &change.text);
                    }
                    None => doc.text = Arc::new(change.text),
                }
                doc.index = Arc::new(LineIndex::new(&doc.text));
            }
            doc.version = version;
            (doc.text.to_string(), doc.file.language(&self.db))
        };
        self.set(&path_of(uri), &text, language);
        self.docs.get(uri)
    }

    /// Forget a document; its file reads from the disk again (it may be a used module).
    pub fn close(&mut self, uri: &Uri) -> Option<Document> {
        let doc = self.docs.remove(uri)?;
        if !doc.read_only {
            let path = path_of(uri);
            if let Some(text) = RealFs.read(&path) {
                let language = doc.file.language(&self.db);
                self.set(&path, &text, language);
            }
        }
        Some(doc)
    }

    /// New options: set in the database, and every open document's modules resolved
    /// again (the region decides a module in scope).
    pub fn set_options(&mut self, options: Options) {
        self.options = options.clone();
        self.db.set_options(options);
        let open: Vec<(PathBuf, String, Language)> = self
            .docs
            .values()
            .filter(|d| !d.read_only)
            .map(|d| (path_of(&d.uri), d.text.to_string(), d.file.language(&self.db)))
            .collect();
        for (path, text, language) in open {
            self.set(&path, &text, language);
        }
    }

    fn set(&mut self, path: &Path, text: &str, language: Language) -> SourceFile {
        let overlay: HashMap<PathBuf, String> =
            self.docs.values().filter(|d| !d.read_only).map(|d| (path_of(&d.uri), d.text.to_string())).collect();
        let file = self.db.set_source(path.to_path_buf(), text.to_string(), language, &Overlay(&overlay));
        // documents that use this one see its new text through the database already;
        // their imports may change when a module they name appears
        let others: Vec<(PathBuf, String, Language)> = self
            .docs
            .values()
            .filter(|d| !d.read_only && d.file != file)
            .map(|d| (path_of(&d.uri), d.text.to_string(), d.file.language(&self.db)))
            .collect();
        for (other, text, language) in others {
            self.db.set_source(other, text, language, &Overlay(&overlay));
        }
        file
    }

    /// The standard module a path in the written stdlib folder is.
    fn standard_file(&self, path: &Path) -> Option<SourceFile> {
        let relative = path.strip_prefix(self.stdlib_dir.as_ref()?).ok()?;
        let name = relative.with_extension("").to_string_lossy().replace(std::path::MAIN_SEPARATOR, ".");
        self.db.standard_module(&name)
    }

    /// Where the open documents and the written stdlib are, for a reader.
    pub fn locator(&self) -> Locator {
        Locator {
            open: self.docs.values().map(|d| (d.file, (d.uri.clone(), d.text.clone(), d.index.clone()))).collect(),
            stdlib_dir: self.stdlib_dir.clone(),
        }
    }

    pub fn doc(&self, uri: &Uri) -> Option<&Document> {
        self.docs.get(uri)
    }
}

/// Where documents without a file path live in the database.
pub const VIRTUAL: &str = "/<unsaved>";

/// The database path of a document.
pub fn path_of(uri: &Uri) -> PathBuf {
    let is_file = uri.scheme().as_str().eq_ignore_ascii_case("file");
    match uri.to_file_path().filter(|_| is_file) {
        Some(path) => path.into_owned(),
        None => {
            let name: String =
                uri.as_str().chars().map(|c| if c.is_ascii_alphanumeric() || c == '.' { c } else { '_' }).collect();
            Path::new(VIRTUAL).join(name)
        }
    }
}

/// Write every embedded standard module, read-only, into a folder named by a hash of
/// their texts (so two versions of the server never share one).
fn write_stdlib() -> Option<PathBuf> {
    let hash =
        tad_base::fnv1a(tad_db::stdlib::MODULES.iter().flat_map(|(name, text)| name.bytes().chain(text.bytes())));
    let dir = std::env::temp_dir().join(format!("tadsl-stdlib-{hash:016x}"));
    for (name, text) in tad_db::stdlib::MODULES {
        let path = dir.join(name.split('.').collect::<PathBuf>().with_extension("tad"));
        if std::fs::read_to_string(&path).is_ok_and(|t| t == *text) {
            continue;
        }
        std::fs::create_dir_all(path.parent()?).ok()?;
        // a name of this call's own: tests open workspaces on several threads of one process
        static CALLS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let partial = path.with_extension(format!("tad.{}.{call}", std::process::id()));
        std::fs::write(&partial, text).ok()?;
        let mut permissions = std::fs::metadata(&partial).ok()?.permissions();
        permissions.set_readonly(true);
        std::fs::set_permissions(&partial, permissions).ok()?;
        std::fs::rename(&partial, &path).ok()?;
    }
    Some(dir)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tower_lsp_server::ls_types::{Position, Range};

    fn uri(path: &str) -> Uri {
        Uri::from_file_path(path).unwrap()
    }

    #[test]
    fn incremental_edits_in_utf16() {
        let mut ws = Workspace::new(Options::default());
        let u = uri("/tmp/tadsl-ws-test/a.tad");
        ws.open(u.clone(), "tad", 1, "// 🚗 é\nscenario x {}\n".to_string());
        let change = |line, from, to, text: &str| TextDocumentContentChangeEvent {
            range: Some(Range { start: Position { line, character: from }, end: Position { line, character: to } }),
            range_length: None,
            text: text.to_string(),
        };
        // replace `é` (UTF-16 column 5, after the surrogate pair) with `e`
        let doc = ws.change(&u, 2, vec![change(0, 6, 7, "e"), change(1, 9, 10, "demo")]).unwrap().clone();
        assert_eq!(doc.text.as_str(), "// 🚗 e\nscenario demo {}\n");
        assert_eq!(doc.file.text(&ws.db), doc.text.as_str());
        assert_eq!(doc.version, 2);
    }

    #[test]
    fn unsaved_modules_win_over_the_disk_and_stdlib_maps_back() {
        let mut ws = Workspace::new(Options::default());
        let module = uri("/tmp/tadsl-ws-test-none/mine.tad");
        ws.open(module.clone(), "tad", 1, "weather glum\n".to_string());
        let main = uri("/tmp/tadsl-ws-test-none/main.tad");
        let doc = ws.open(main, "tad", 1, "use mine\n".to_string()).clone();
        let modules = ws.db.local_modules(doc.file);
        assert_eq!(modules.len(), 1, "the open module resolves without a file on disk");
        // the stdlib opens as the embedded module, read-only
        let core = ws.db.standard_module("core").unwrap();
        let dir = ws.locator().stdlib_dir.expect("the stdlib is written");
        let core_uri = Uri::from_file_path(dir.join("core.tad")).unwrap();
        let opened = ws.open(core_uri, "tad", 1, "weather clear\n".to_string()).clone();
        assert!(opened.read_only);
        assert_eq!(opened.file, core);
        assert!(opened.text.contains("weather clear {"));
    }

    #[test]
    fn untitled_documents_get_a_virtual_path() {
        let u: Uri = "untitled:Untitled-1".parse().unwrap();
        assert!(path_of(&u).starts_with(VIRTUAL));
        let mut ws = Workspace::new(Options::default());
        let file = ws.open(u.clone(), "tad", 1, "scenario".to_string()).file;
        assert_eq!(ws.locator().open.get(&file).map(|o| &o.0), Some(&u), "an open document is found by its file");
    }
}
