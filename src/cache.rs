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
//! changed, appeared or vanished misses.
//!
//! Entries are kept in packs, one file per input folder and scope (the key's
//! parts other than the input: build, working directory, config, options),
//! as ruff keeps one file per package: a pack is written once its folder is
//! checked, whole to a temporary file and renamed, so runs sharing the
//! cache (CI shards, which deal out folders whole) never read half of one.
//!
//! Old packs are pruned by age, not by the last run: a pack's modification
//! time is its last use (a read refreshes it when it is over a day old),
//! and at most once a day a run removes packs unused for [`MAX_AGE`] and
//! temporary files of runs that died. Pruning what the current run did not
//! use would throw away the other shards' packs (shards share the folder)
//! and a whole tree's after a run over one folder; ruff's cache likewise
//! drops files it has not seen for a while. Within a pack, an entry goes
//! when the pack is written again and its input no longer exists.

use crate::diag::{Diagnostic, Fix, Label, Severity};
use std::collections::{BTreeMap, HashMap, HashSet};
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
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
#[derive(Clone)]
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
    deps: Mutex<HashMap<PathBuf, Option<String>>>,
    /// Packs read or written this run and not yet flushed, by pack id.
    packs: Mutex<HashMap<Key, Arc<Mutex<Pack>>>>,
}

/// The entries of one folder's inputs (or loose pipelines) under one scope
/// (build, working directory, config and options), stored as one file.
///
/// One file per input made a cold run over 10,000 files spend more time
/// creating files than checking them (about 0.8 ms of kernel time per new
/// file on ext4 here: 12.0 s CPU against 3.7 s without the cache); a pack
/// per folder writes 25 times fewer. Each scope has its own pack, so runs
/// under different configs do not evict each other's entries.
#[derive(Debug)]
struct Pack {
    /// The folder: an untouched entry whose file is gone is dropped when
    /// the pack is written again.
    folder: PathBuf,
    slots: BTreeMap<String, Slot>,
    /// Slots looked up or written this run.
    touched: HashSet<String>,
    dirty: bool,
}

/// One entry of a pack: its full key, and the entry as JSON text (parsed
/// only when a lookup hits).
#[derive(Debug, serde::Serialize, serde::Deserialize)]
struct Slot {
    key: String,
    entry: Box<serde_json::value::RawValue>,
}

#[derive(serde::Serialize, serde::Deserialize)]
struct PackFile {
    slots: BTreeMap<String, Slot>,
}

/// How a loose pipeline group's slot name starts (an input's slot is its
/// file name; were the two names ever equal, the keys still differ, so the
/// worst is a miss).
const GROUP_SLOT: &str = "group ";

/// The slot of a loose pipeline group (its path is a folder or a file).
fn group_slot(group: &Path) -> String {
    format!("{GROUP_SLOT}{}", group.display())
}

/// An input's slot: its file name within its folder.
fn input_slot(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// An input's folder, as the input names it (its pack's scope holds the
/// working directory, so a relative folder is unambiguous).
fn folder_of(path: &Path) -> &Path {
    named(path.parent().unwrap_or(Path::new("")))
}

/// A folder as packs name it: the working directory is `.`.
fn named(folder: &Path) -> &Path {
    if folder.as_os_str().is_empty() {
        Path::new(".")
    } else {
        folder
    }
}

impl Cache {
    /// Opens (and creates) the folder; `None` when it cannot be created, so a
    /// read-only checkout still lints, uncached.
    pub fn open(dir: &Path) -> Option<Cache> {
        std::fs::create_dir_all(dir.join("packs")).ok()?;
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
            packs: Default::default(),
        })
    }

    fn pack_path(&self, id: Key) -> PathBuf {
        self.dir.join("packs").join(format!("{}.json", id.hex()))
    }

    /// The pack of `folder` under `scope`, read from disk the first time
    /// this run asks.
    fn pack(&self, scope: Key, folder: &Path) -> Arc<Mutex<Pack>> {
        let id = KeyBuilder::default()
            .add(scope)
            .add(folder.as_os_str())
            .finish();
        let Ok(mut packs) = self.packs.lock() else {
            return Arc::new(Mutex::new(Pack::empty(folder)));
        };
        packs
            .entry(id)
            .or_insert_with(|| Arc::new(Mutex::new(self.read_pack(id, folder))))
            .clone()
    }

    fn read_pack(&self, id: Key, folder: &Path) -> Pack {
        use std::io::Read;
        let path = self.pack_path(id);
        let mut pack = Pack::empty(folder);
        let Ok(mut file) = std::fs::File::open(&path) else {
            return pack;
        };
        let Ok(meta) = file.metadata() else {
            return pack;
        };
        let mut bytes = Vec::with_capacity(meta.len() as usize);
        if file.read_to_end(&mut bytes).is_err() {
            return pack;
        }
        let Ok(stored) = serde_json::from_slice::<PackFile>(&bytes) else {
            return pack;
        };
        pack.slots = stored.slots;
        // Read is use: keep the pack from being pruned.
        let old = meta
            .modified()
            .ok()
            .and_then(|m| SystemTime::now().duration_since(m).ok())
            .is_some_and(|a| a > PRUNE_EVERY);
        if old {
            if let Ok(f) = std::fs::File::options().write(true).open(&path) {
                let _ = f.set_modified(SystemTime::now());
            }
        }
        pack
    }

    fn read<T: serde::de::DeserializeOwned>(
        &self,
        scope: Key,
        folder: &Path,
        slot: String,
        key: Key,
    ) -> Option<T> {
        let pack = self.pack(scope, folder);
        let text = {
            let mut pack = pack.lock().ok()?;
            let found = pack.slots.get(&slot)?;
            if found.key != key.hex() {
                return None;
            }
            let text = found.entry.get().to_owned();
            pack.touched.insert(slot);
            text
        };
        serde_json::from_str(&text).ok()
    }

    fn write<T: serde::Serialize>(
        &self,
        scope: Key,
        folder: &Path,
        slot: String,
        key: Key,
        value: &T,
    ) {
        let Ok(entry) = serde_json::value::to_raw_value(value) else {
            return;
        };
        let pack = self.pack(scope, folder);
        let Ok(mut pack) = pack.lock() else {
            return;
        };
        pack.touched.insert(slot.clone());
        pack.slots.insert(
            slot,
            Slot {
                key: key.hex(),
                entry,
            },
        );
        pack.dirty = true;
    }

    /// The entry of input `path` under `scope` for `key`, when its
    /// dependencies are unchanged.
    pub fn get(&self, scope: Key, path: &Path, key: Key) -> Option<Entry> {
        let entry: Entry = self.read(scope, folder_of(path), input_slot(path), key)?;
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

    /// Stores input `path`'s entry (written when its folder is flushed).
    pub fn put(&self, scope: Key, path: &Path, key: Key, entry: &Entry) {
        self.write(scope, folder_of(path), input_slot(path), key, entry);
    }

    /// The entry of loose pipeline `group`, whose members are in `folder`.
    pub fn get_group(
        &self,
        scope: Key,
        folder: &Path,
        group: &Path,
        key: Key,
    ) -> Option<GroupEntry> {
        self.read(scope, named(folder), group_slot(group), key)
    }

    pub fn put_group(&self, scope: Key, folder: &Path, group: &Path, key: Key, entry: &GroupEntry) {
        self.write(scope, named(folder), group_slot(group), key, entry);
    }

    /// Writes the packs of `folder` (as inputs name it) that changed, and
    /// forgets them: call once the run has checked all of that folder.
    pub fn flush(&self, folder: &Path) {
        let folder = named(folder);
        let done: Vec<(Key, Arc<Mutex<Pack>>)> = match self.packs.lock() {
            Ok(mut packs) => {
                let ids: Vec<Key> = packs
                    .iter()
                    .filter(|(_, p)| p.lock().is_ok_and(|p| p.folder == folder))
                    .map(|(id, _)| *id)
                    .collect();
                ids.into_iter()
                    .filter_map(|id| packs.remove(&id).map(|p| (id, p)))
                    .collect()
            }
            Err(_) => return,
        };
        for (id, pack) in done {
            self.write_pack(id, &pack);
        }
    }

    /// Writes every changed pack: at the end of a run.
    pub fn flush_all(&self) {
        let all: Vec<(Key, Arc<Mutex<Pack>>)> = match self.packs.lock() {
            Ok(mut packs) => packs.drain().collect(),
            Err(_) => return,
        };
        for (id, pack) in all {
            self.write_pack(id, &pack);
        }
    }

    fn write_pack(&self, id: Key, pack: &Mutex<Pack>) {
        let Ok(mut pack) = pack.lock() else {
            return;
        };
        if !pack.dirty {
            return;
        }
        // Entries of inputs that are gone leave with the next write; the
        // others stay (a run over part of a folder keeps the rest).
        let Pack {
            folder,
            slots,
            touched,
            ..
        } = &mut *pack;
        slots.retain(|name, _| {
            touched.contains(name) || name.starts_with(GROUP_SLOT) || folder.join(name).exists()
        });
        let file = PackFile {
            slots: std::mem::take(slots),
        };
        let Ok(bytes) = serde_json::to_vec(&file) else {
            return;
        };
        let path = self.pack_path(id);
        // Unique per process and thread, renamed into place whole: runs
        // sharing the folder never read half a pack (two runs writing one
        // pack at once: the last one's stays, the other's entries miss).
        let tmp = path.with_extension(format!(
            "{}.{:?}.tmp",
            std::process::id(),
            std::thread::current().id()
        ));
        if std::fs::write(&tmp, bytes).is_ok() && std::fs::rename(&tmp, &path).is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
    }

    /// Removes packs unused for [`MAX_AGE`] and temporary files of runs
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
        // `files` and `groups`: one entry per file, as older builds wrote;
        // `modules`: compiled GLSL (`front::glsl`), recompiled when pruned.
        for kind in ["packs", "files", "groups", "modules"] {
            let Ok(dir) = std::fs::read_dir(self.dir.join(kind)) else {
                continue;
            };
            for e in dir.flatten() {
                let path = e.path();
                let limit = match path.extension().and_then(|x| x.to_str()) {
                    Some("json" | "spv" | "deps") => MAX_AGE,
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

impl Pack {
    fn empty(folder: &Path) -> Pack {
        Pack {
            folder: folder.to_path_buf(),
            slots: BTreeMap::new(),
            touched: HashSet::new(),
            dirty: false,
        }
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
