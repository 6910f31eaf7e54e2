//! Slang, loaded at run time: the second HLSL compiler rtlint's own is
//! checked against (tests, benches, examples; never the library).
//! `pip install slangpy` ships `libslang-compiler.so`; its C API
//! (`spCreateSession`, `spCompile`, …) is driven with slangc-style arguments.

use libloading::{Library, Symbol};
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};

type CreateSession = unsafe extern "C" fn(*const c_char) -> *mut c_void;
type DestroySession = unsafe extern "C" fn(*mut c_void);
type CreateRequest = unsafe extern "C" fn(*mut c_void) -> *mut c_void;
type DestroyRequest = unsafe extern "C" fn(*mut c_void);
type ProcessArgs = unsafe extern "C" fn(*mut c_void, *const *const c_char, c_int) -> i32;
type Compile = unsafe extern "C" fn(*mut c_void) -> i32;
type Diagnostics = unsafe extern "C" fn(*mut c_void) -> *const c_char;
type RequestCode = unsafe extern "C" fn(*mut c_void, *mut usize) -> *const c_void;

/// A loaded Slang compiler with one global session (creating it costs ≈0.1 s).
pub struct Slang {
    session: *mut c_void,
    lib: Library,
    pub path: PathBuf,
}

/// The Slang stage name of a ray-tracing or compute entry point.
pub fn stage_name(stage: rtlint::shader::Stage) -> &'static str {
    use rtlint::shader::Stage as S;
    match stage {
        S::RayGeneration => "raygeneration",
        S::Intersection => "intersection",
        S::AnyHit => "anyhit",
        S::ClosestHit => "closesthit",
        S::Miss => "miss",
        S::Callable => "callable",
        S::Compute => "compute",
        S::Vertex => "vertex",
        S::Fragment => "fragment",
        S::Other => "",
    }
}

/// Where `libslang-compiler.so` is: `RTLINT_SLANG_LIB`, else inside the
/// `slangpy` Python package (found without importing it).
pub fn find_library() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("RTLINT_SLANG_LIB") {
        return Some(PathBuf::from(p));
    }
    let out = std::process::Command::new("python3")
        .args([
            "-c",
            "import importlib.util as u; s = u.find_spec('slangpy'); print(s.submodule_search_locations[0] if s else '')",
        ])
        .output()
        .ok()?;
    let dir = PathBuf::from(String::from_utf8(out.stdout).ok()?.trim());
    let mut libs: Vec<PathBuf> = std::fs::read_dir(&dir)
        .ok()?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("libslang-compiler.so") || n == "libslang.so")
        })
        .collect();
    libs.sort();
    libs.pop()
}

impl Slang {
    pub fn load(path: &Path) -> Result<Slang, String> {
        // SAFETY: loading a library runs its initialisers; libslang's are benign.
        let lib = unsafe { Library::new(path) }
            .map_err(|e| format!("cannot load {}: {e}", path.display()))?;
        let session = unsafe {
            let create: Symbol<CreateSession> = sym(&lib, b"spCreateSession\0")?;
            create(std::ptr::null())
        };
        if session.is_null() {
            return Err("spCreateSession returned null".into());
        }
        Ok(Slang {
            session,
            lib,
            path: path.to_path_buf(),
        })
    }

    /// Finds and loads Slang.
    pub fn find() -> Result<Slang, String> {
        let path = find_library().ok_or(
            "Slang not found: `pip install slangpy` (scripts/setup does) or set RTLINT_SLANG_LIB to libslang-compiler.so",
        )?;
        Slang::load(&path)
    }

    /// Compiles one entry point of an HLSL file to SPIR-V 1.4 words.
    /// `extra` takes further slangc arguments (`-I dir`, `-D NAME=VALUE`).
    pub fn compile_hlsl(
        &self,
        file: &Path,
        entry: &str,
        stage: &str,
        extra: &[String],
    ) -> Result<Vec<u32>, String> {
        let mut args: Vec<String> = vec![
            "-lang".into(),
            "hlsl".into(),
            file.to_string_lossy().into_owned(),
        ];
        args.extend(extra.iter().cloned());
        args.extend(
            [
                "-target",
                "spirv",
                "-profile",
                "spirv_1_4",
                "-entry",
                entry,
                "-stage",
                stage,
            ]
            .iter()
            .map(|s| s.to_string()),
        );
        let cargs: Vec<CString> = args
            .iter()
            .map(|a| {
                CString::new(a.as_str()).map_err(|_| format!("argument `{a}` contains a NUL byte"))
            })
            .collect::<Result<_, _>>()?;
        let argv: Vec<*const c_char> = cargs.iter().map(|c| c.as_ptr()).collect();
        // SAFETY: the symbols have the C signatures of slang.h; the request is
        // destroyed on every path and the code is copied out before that.
        unsafe {
            let create: Symbol<CreateRequest> = sym(&self.lib, b"spCreateCompileRequest\0")?;
            let destroy: Symbol<DestroyRequest> = sym(&self.lib, b"spDestroyCompileRequest\0")?;
            let process: Symbol<ProcessArgs> = sym(&self.lib, b"spProcessCommandLineArguments\0")?;
            let compile: Symbol<Compile> = sym(&self.lib, b"spCompile\0")?;
            let diagnostics: Symbol<Diagnostics> = sym(&self.lib, b"spGetDiagnosticOutput\0")?;
            let code: Symbol<RequestCode> = sym(&self.lib, b"spGetCompileRequestCode\0")?;
            let req = create(self.session);
            if req.is_null() {
                return Err("spCreateCompileRequest returned null".into());
            }
            let diag = |req| {
                let p = diagnostics(req);
                if p.is_null() {
                    String::new()
                } else {
                    CStr::from_ptr(p).to_string_lossy().trim().to_string()
                }
            };
            let result = (|| {
                if process(req, argv.as_ptr(), argv.len() as c_int) < 0 {
                    return Err(format!("slang rejected the arguments: {}", diag(req)));
                }
                if compile(req) < 0 {
                    return Err(format!(
                        "slang failed to compile {}: {}",
                        file.display(),
                        diag(req)
                    ));
                }
                let mut size = 0usize;
                let ptr = code(req, &mut size);
                if ptr.is_null() || size < 20 || size % 4 != 0 {
                    return Err(format!(
                        "slang returned no SPIR-V ({size} bytes): {}",
                        diag(req)
                    ));
                }
                let bytes = std::slice::from_raw_parts(ptr as *const u8, size);
                Ok(bytes
                    .chunks_exact(4)
                    .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                    .collect())
            })();
            destroy(req);
            result
        }
    }
}

impl Drop for Slang {
    fn drop(&mut self) {
        // SAFETY: the session was created by this library and is dropped once.
        unsafe {
            if let Ok(destroy) = sym::<DestroySession>(&self.lib, b"spDestroySession\0") {
                destroy(self.session);
            }
        }
    }
}

unsafe fn sym<'a, T>(lib: &'a Library, name: &[u8]) -> Result<Symbol<'a, T>, String> {
    lib.get(name).map_err(|e| {
        format!(
            "libslang lacks {}: {e}",
            String::from_utf8_lossy(&name[..name.len() - 1])
        )
    })
}
