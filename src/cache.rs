//! The result cache of `rtlint check` (`.rtlint_cache`, as ruff's
//! `.ruff_cache`): one entry per input, keyed by everything its findings
//! depend on, so an unchanged tree is re-checked by reading and hashing its
//! files instead of compiling and analysing them.
//!
//! The key of an input hashes the rtlint build (version and the running
//! executable's size and time, so a rebuilt binary never reads an older
//! one's results), the working directory, the input's path, language and
//! contents, the effective config (after the command line's overrides) and
//! the front-end options. Files the input pulls in (includes, the sources
//! its debug info names) are known only after compiling: the entry lists
//! them with a hash of their contents, and a lookup whose listed file
//! changed, appeared or vanished misses. Entries are written whole to a
//! temporary file and renamed, so runs sharing the folder (CI shards) never
//! read half an entry.
//!
//! Old entries are pruned by age, not by the last run: an entry's
//! modification time is its last use (a hit refreshes it when it is over a
//! day old), and at most once a day a run removes entries unused for
//! [`MAX_AGE`] and temporary files of runs that died. Pruning what the
//! current run did not use would throw away the other shards' entries
//! (shards share the folder) and a whole tree's after a run over one
//! folder; ruff's cache likewise drops files it has not seen for a while.

use crate::diag::{Diagnostic, Fix, Label, Severity};
use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

/// Where the CLI keeps its cache when neither `--cache-dir` nor
/// `RTLINT_CACHE_DIR` says: this folder in the working directory.
pub const DEFAULT_DIR: &str = ".rtlint_cache";

/// Entries unused for this long are removed.
pub const MAX_AGE: Duration = Duration::from_secs(30 * 24 * 60 * 60);

/// How often a run looks for old entries, and how stale a hit's time may
/// get before the hit refreshes it (one write per entry per day at most).
pub const PRUNE_EVERY: Duration = Duration::from_secs(24 * 60 * 60);

/// A temporary file this old belongs to a run that died.
const TMP_AGE: Duration = Duration::from_secs(60 * 60);

/// A 128-bit content hash (two SipHash passes with different prefixes):
/// wide enough that a collision between two inputs is not a concern.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Key(u64, u64);

impl Key {
    pub fn hex(self) -> String {
        format!("{:016x}{:016x}", self.0, self.1)
    }
}

/// Builds a [`Key`] from parts.
pub struct KeyBuilder(
    std::collections::hash_map::DefaultHasher,
    std::collections::hash_map::DefaultHasher,
);

impl Default for KeyBuilder {
    fn default() -> Self {
        let a = std::collections::hash_map::DefaultHasher::new();
        let mut b = std::collections::hash_map::DefaultHasher::new();
        b.write_u64(0x9e37_79b9_7f4a_7c15);
        KeyBuilder(a, b)
    }
}

impl KeyBuilder {
    pub fn add(&mut self, part: impl Hash) -> &mut Self {
        part.hash(&mut self.0);
        part.hash(&mut self.1);
        self
    }

    /// Adds a file's bytes in one pass (the file is the bulk of what a
    /// key hashes; `add` would hash it twice): the two halves share this
    /// 64-bit digest, a collision of which between two versions of one
    /// input path is still not a concern.
    pub fn add_bytes(&mut self, bytes: &[u8]) -> &mut Self {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        h.write(bytes);
        self.add((bytes.len(), h.finish()))
    }

    pub fn finish(&self) -> Key {
        Key(self.0.finish(), self.1.finish())
    }
}

/// The hash of a file's bytes.
pub fn content_key(bytes: &[u8]) -> Key {
    KeyBuilder::default().add(bytes).finish()
}

/// The running build: a rebuilt binary of the same version does not trust
/// its predecessor's results.
fn build_id() -> &'static str {
    static ID: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    ID.get_or_init(|| {
        let exe = std::env::current_exe()
            .ok()
            .and_then(|p| std::fs::metadata(p).ok())
            .map(|m| {
                let t = m
                    .modified()
                    .ok()
                    .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
                    .map(|d| d.as_nanos())
                    .unwrap_or(0);
                format!("{}-{t}", m.len())
            })
            .unwrap_or_default();
        format!("{}-{exe}", env!("CARGO_PKG_VERSION"))
    })
}

/// What every key starts with: the build and the working directory (paths
/// in findings and includes are relative to it).
pub fn base_key() -> KeyBuilder {
    let mut k = KeyBuilder::default();
    k.add(build_id())
        .add(std::env::current_dir().unwrap_or_default());
    k
}

/// One input's cached outcome.
#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Entry {
    /// Files the result depends on besides the input, with their contents'
    /// hash (`None`: the file did not exist).
    pub deps: Vec<(PathBuf, Option<String>)>,
    /// The source files of the module and the text it embeds.
    pub files: Vec<(PathBuf, Option<String>)>,
    pub diagnostics: Vec<CachedDiagnostic>,
    /// The folder (or file) whose loose shaders form one pipeline with this
    /// one; `None` without ray-tracing entry points.
    pub group: Option<PathBuf>,
}

/// A pipeline group's findings.
#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct GroupEntry {
    pub diagnostics: Vec<CachedDiagnostic>,
}

/// A rule finding as stored: code and name as text.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct CachedDiagnostic {
    code: String,
    name: String,
    severity: Severity,
    message: String,
    file: PathBuf,
    primary: Option<Label>,
    secondary: Vec<Label>,
    subject: Option<String>,
    notes: Vec<String>,
    help: Option<String>,
    fix: Option<Fix>,
}

impl CachedDiagnostic {
    /// Only rule findings are stored (input errors are not cached).
    pub fn new(d: &Diagnostic) -> Option<Self> {
        Some(CachedDiagnostic {
            code: d.code?.to_string(),
            name: d.name.to_string(),
            severity: d.severity,
            message: d.message.clone(),
            file: d.file.clone(),
            primary: d.primary.clone(),
            secondary: d.secondary.clone(),
            subject: d.subject.clone(),
            notes: d.notes.clone(),
            help: d.help.clone(),
            fix: d.fix.clone(),
        })
    }

    /// `None` when the code no longer names a rule of that name.
    pub fn diagnostic(self) -> Option<Diagnostic> {
        let rule = crate::rules::find(&self.code).filter(|r| r.name == self.name)?;
        let mut d = Diagnostic::new(self.severity, rule.name, &self.file, self.message)
            .with_code(rule.code);
        d.primary = self.primary;
        d.secondary = self.secondary;
        d.subject = self.subject;
        d.notes = self.notes;
        d.help = self.help;
        d.fix = self.fix;
        Some(d)
    }
}

/// Stores findings as entries: all of them, or `None` when one cannot be
/// stored (an input error).
pub fn store_all(diagnostics: &[Diagnostic]) -> Option<Vec<CachedDiagnostic>> {
    diagnostics.iter().map(CachedDiagnostic::new).collect()
}

/// Turns stored findings back, or `None` when one no longer fits the rules.
pub fn load_all(stored: Vec<CachedDiagnostic>) -> Option<Vec<Diagnostic>> {
    stored
        .into_iter()
        .map(CachedDiagnostic::diagnostic)
        .collect()
}

/// The cache folder.
#[derive(Debug)]
pub struct Cache {
    dir: PathBuf,
    /// Dependencies' hashes, each computed once a run: many inputs share a
    /// header, and files do not change under a run.
    deps: std::sync::Mutex<HashMap<PathBuf, Option<String>>>,
}

impl Cache {
    /// Opens (and creates) the folder; `None` when it cannot be created, so a
    /// read-only checkout still lints, uncached.
    pub fn open(dir: &Path) -> Option<Cache> {
        std::fs::create_dir_all(dir.join("files")).ok()?;
        std::fs::create_dir_all(dir.join("groups")).ok()?;
        // As ruff does: the folder ignores itself and says what it is.
        let ignore = dir.join(".gitignore");
        if !ignore.exists() {
            let _ = std::fs::write(&ignore, "# Created by rtlint automatically.\n*\n");
        }
        let tag = dir.join("CACHEDIR.TAG");
        if !tag.exists() {
            let _ = std::fs::write(
                &tag,
                "Signature: 8a477f597d28d172789f06886806bc55\n# This file is a cache directory tag created by rtlint.\n",
            );
        }
        Some(Cache {
            dir: dir.to_path_buf(),
            deps: Default::default(),
        })
    }

    fn path(&self, kind: &str, key: Key) -> PathBuf {
        self.dir.join(kind).join(format!("{}.json", key.hex()))
    }

    fn read<T: serde::de::DeserializeOwned>(&self, kind: &str, key: Key) -> Option<T> {
        use std::io::Read;
        let path = self.path(kind, key);
        let mut file = std::fs::File::open(&path).ok()?;
        // One look at the open file: its size, and its time below.
        let meta = file.metadata().ok()?;
        let mut bytes = Vec::with_capacity(meta.len() as usize);
        file.read_to_end(&mut bytes).ok()?;
        let value = serde_json::from_slice(&bytes).ok()?;
        // A hit is a use: keep the entry from being pruned.
        let modified = meta.modified().ok();
        let old = modified
            .and_then(|m| SystemTime::now().duration_since(m).ok())
            .is_some_and(|a| a > PRUNE_EVERY);
        if old {
            if let Ok(f) = std::fs::File::options().write(true).open(&path) {
                let _ = f.set_modified(SystemTime::now());
            }
        }
        Some(value)
    }

    fn write<T: serde::Serialize>(&self, kind: &str, key: Key, value: &T) {
        let Ok(bytes) = serde_json::to_vec(value) else {
            return;
        };
        let path = self.path(kind, key);
        // Unique per process and thread, renamed into place whole.
        let tmp = path.with_extension(format!(
            "{}.{:?}.tmp",
            std::process::id(),
            std::thread::current().id()
        ));
        if std::fs::write(&tmp, bytes).is_ok() && std::fs::rename(&tmp, &path).is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
    }

    /// The entry for `key` whose dependencies are unchanged.
    pub fn get(&self, key: Key) -> Option<Entry> {
        let entry: Entry = self.read("files", key)?;
        entry
            .deps
            .iter()
            .all(|(p, h)| self.dep_hash(p) == *h)
            .then_some(entry)
    }

    /// [`dep_hash`], once per path and run.
    pub fn dep_hash(&self, path: &Path) -> Option<String> {
        if let Some(h) = self.deps.lock().ok().and_then(|m| m.get(path).cloned()) {
            return h;
        }
        // Hashed outside the lock: two threads may both hash a file once.
        let h = dep_hash(path);
        if let Ok(mut m) = self.deps.lock() {
            m.insert(path.to_path_buf(), h.clone());
        }
        h
    }

    pub fn put(&self, key: Key, entry: &Entry) {
        self.write("files", key, entry);
    }

    pub fn get_group(&self, key: Key) -> Option<GroupEntry> {
        self.read("groups", key)
    }

    pub fn put_group(&self, key: Key, entry: &GroupEntry) {
        self.write("groups", key, entry);
    }

    /// Removes entries unused for [`MAX_AGE`] and temporary files of runs
    /// that died, when the last look was over [`PRUNE_EVERY`] ago (a marker
    /// file's time says when). Returns how many files went.
    pub fn prune(&self) -> usize {
        let marker = self.dir.join("last-prune");
        if age(&marker).is_some_and(|a| a < PRUNE_EVERY) {
            return 0;
        }
        // Claimed first, so that runs finishing together do not all walk.
        if std::fs::write(&marker, "").is_err() {
            return 0;
        }
        let mut removed = 0;
        for kind in ["files", "groups"] {
            let Ok(dir) = std::fs::read_dir(self.dir.join(kind)) else {
                continue;
            };
            for e in dir.flatten() {
                let path = e.path();
                let limit = match path.extension().and_then(|x| x.to_str()) {
                    Some("json") => MAX_AGE,
                    Some("tmp") => TMP_AGE,
                    _ => continue,
                };
                if age(&path).is_some_and(|a| a > limit) && std::fs::remove_file(&path).is_ok() {
                    removed += 1;
                }
            }
        }
        removed
    }
}

/// How long ago `path` was last modified (`None`: it does not exist, or
/// its time is in the future).
fn age(path: &Path) -> Option<Duration> {
    let modified = std::fs::metadata(path).ok()?.modified().ok()?;
    SystemTime::now().duration_since(modified).ok()
}

/// A dependency's contents hash as an entry stores it.
pub fn dep_hash(path: &Path) -> Option<String> {
    std::fs::read(path).ok().map(|b| content_key(&b).hex())
}
