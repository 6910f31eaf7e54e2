//! `rtlint verify`: runs the reference reflection shaders on the Vulkan
//! device and compares every image with the CPU reference renderer
//! ([`crate::reference`]).
//!
//! What runs is data: a manifest (`shaders/verify.toml`) names each shader's
//! pipeline description, which CPU reference follows its math, and the
//! scenes (`scenes/*.toml`) it renders. Every GPU run happens in a child
//! process (lavapipe kills the process on recursion past the declared
//! depth): the caller says how to start one ([`Options::child`]), and the
//! child calls [`child_main`]. One case is an *expected failure*: a pipeline
//! declared with less recursion depth than it needs, which passes when the
//! child's crash is caught.

pub mod bundled;
pub mod compare;
pub mod gpu;
pub mod measure;

use crate::reference::{self, Method, Params, Scene};
use crate::vk::{spawn_command, ChildOutcome, RunningChild};
use compare::Comparison;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// Tolerance per 8-bit channel: the GPU and the CPU evaluate the same f32
/// expressions, but the driver may fuse multiply-adds and use its own
/// `normalize`, so a value close to a rounding boundary can land one step away.
pub const TOLERANCE: u8 = 1;

/// How long one child may run.
pub const CHILD_TIMEOUT: Duration = Duration::from_secs(120);

/// The exit code of a child whose device cannot run its case, and the
/// error [`child_main`] returns then (the CLI maps it to that code).
pub const SKIP_CODE: i32 = 77;
pub const SKIP: &str = "skipped: the device cannot run this case";

/// The manifest's file name inside the shaders folder.
pub const MANIFEST: &str = "verify.toml";

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawManifest {
    width: u32,
    height: u32,
    #[serde(default)]
    shader: Vec<RawShader>,
    #[serde(default)]
    expected_failure: Vec<RawExpectedFailure>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawShader {
    name: String,
    /// A ray-tracing pipeline description, or
    pipeline: Option<PathBuf>,
    /// a compute shader (ray queries) with its entry point and bounces.
    compute: Option<PathBuf>,
    entry: Option<String>,
    /// The compute entry point for scenes with alpha-tested cut-outs (it
    /// binds the alpha texture; `entry` does not).
    cutout_entry: Option<String>,
    max_bounces: Option<u32>,
    reference: String,
    scenes: Vec<String>,
    /// Shaders whose images this one's must equal, on the scenes both render.
    #[serde(default)]
    identical_to: OneOrMany,
}

/// A name, or a list of them.
#[derive(Deserialize, Default)]
#[serde(untagged)]
enum OneOrMany {
    #[default]
    None,
    One(String),
    Many(Vec<String>),
}

impl OneOrMany {
    fn names(&self) -> &[String] {
        match self {
            OneOrMany::None => &[],
            OneOrMany::One(n) => std::slice::from_ref(n),
            OneOrMany::Many(v) => v,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawExpectedFailure {
    name: String,
    pipeline: PathBuf,
    /// Declared instead of the description's own depth.
    max_recursion_depth: u32,
    reference: String,
    scene: String,
}

/// What runs on the device.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// A ray-tracing pipeline description.
    Pipeline(PathBuf),
    /// A compute shader using ray queries: one invocation per pixel.
    Compute {
        file: PathBuf,
        entry: String,
        /// The entry point for scenes with cut-outs.
        cutout_entry: Option<String>,
        max_bounces: u32,
    },
}

/// One cell of the numerical-extremes matrix: a variant of the scene or the
/// ray parameters, rendered with robust origins or the fixed epsilon.
#[derive(Clone, Debug, PartialEq)]
pub struct Extreme {
    /// `translate=1e3`, `tmax=inf`, `tmin=1e-3`, `roughness=0.5`, `grazing`,
    /// `backfacing`.
    pub variant: String,
    pub robust: bool,
}

/// The variants of the matrix, each rendered both ways.
pub const EXTREMES: [&str; 15] = [
    "translate=0",
    "translate=1e3",
    "translate=1e4",
    "translate=1e5",
    "translate=1e6",
    "tmax=1e-3",
    "tmax=1e4",
    "tmax=inf",
    "tmin=1e-3",
    "roughness=0",
    "roughness=1e-4",
    "roughness=0.5",
    "roughness=1",
    "grazing",
    "backfacing",
];

impl Extreme {
    /// Changes the scene and the parameters as the variant says.
    pub fn apply(&self, scene: &mut Scene, params: &mut Params) -> Result<(), String> {
        params.robust = self.robust;
        let number = |v: &str| -> Result<f32, String> {
            if v == "inf" {
                Ok(f32::INFINITY)
            } else {
                v.parse::<f32>()
                    .map_err(|_| format!("bad extreme value `{v}` in `{}`", self.variant))
            }
        };
        match self.variant.split_once('=') {
            Some(("translate", v)) => {
                *scene = scene.translated(reference::Vec3::splat(number(v)?));
                params.camera = scene.camera;
            }
            Some(("tmax", v)) => params.t_max = number(v)?,
            Some(("tmin", v)) => params.t_min = number(v)?,
            Some(("roughness", v)) => *scene = scene.with_roughness(number(v)?),
            None if self.variant == "grazing" => {
                // Just above the mirror floor: primary rays meet it with N·V → 0.
                scene.camera.y = 1e-3;
                params.camera = scene.camera;
            }
            // Every normal in the surfaces buffer faces away from the viewer:
            // the shaders must turn it towards the ray before shading.
            None if self.variant == "backfacing" => *scene = scene.with_flipped_normals(),
            _ => return Err(format!("unknown extreme `{}`", self.variant)),
        }
        Ok(())
    }
}

/// One row of the table.
#[derive(Clone, Debug, PartialEq)]
pub enum CaseKind {
    /// Render `scene` and compare with the CPU reference.
    Render {
        source: Source,
        method: Method,
        scene: PathBuf,
        /// A cell of the numerical-extremes matrix: how the scene and the
        /// parameters are changed.
        extreme: Option<Extreme>,
    },
    /// The GPU images of two render cases are identical.
    Identical { a: String, b: String },
    /// A run that must crash the child: the pipeline declared with
    /// `depth`, less recursion depth than it needs. It fails if the child
    /// runs clean.
    ExpectedCrash {
        source: Source,
        method: Method,
        scene: PathBuf,
        depth: u32,
    },
}

impl CaseKind {
    /// What a case runs on the device: pipeline, scene, and the recursion
    /// depth declared instead of the description's.
    pub fn runs(&self) -> Option<(&Source, &Path, Option<u32>)> {
        match self {
            CaseKind::Render { source, scene, .. } => Some((source, scene, None)),
            CaseKind::ExpectedCrash {
                source,
                scene,
                depth,
                ..
            } => Some((source, scene, Some(*depth))),
            CaseKind::Identical { .. } => None,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// `shader/scene`, unique; `--filter` matches it.
    pub name: String,
    pub shader: String,
    pub scene: String,
    pub kind: CaseKind,
}

/// The manifest, resolved.
#[derive(Clone, Debug)]
pub struct Manifest {
    pub width: u32,
    pub height: u32,
    pub cases: Vec<Case>,
}

fn method(name: &str, what: &str) -> Result<Method, String> {
    match name {
        "iterative" => Ok(Method::Iterative),
        "recursive" => Ok(Method::Recursive),
        "glossy" => Ok(Method::Glossy),
        "hybrid" => Ok(Method::Hybrid),
        "adaptive" => Ok(Method::Adaptive),
        other => Err(format!(
            "{what}: unknown reference `{other}` (expected `iterative`, `recursive`, `glossy`, `hybrid` or `adaptive`)"
        )),
    }
}

impl Manifest {
    /// Reads `DIR/verify.toml`; paths in it are relative to `DIR`.
    pub fn load(dir: &Path) -> Result<Manifest, String> {
        let path = dir.join(MANIFEST);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        let raw: RawManifest = toml::from_str(&text)
            .map_err(|e| format!("{}: {}", path.display(), e.message().trim()))?;
        if raw.width == 0 || raw.height == 0 || raw.width > 4096 || raw.height > 4096 {
            return Err(format!(
                "{}: width and height must be 1–4096",
                path.display()
            ));
        }
        let scene = |name: &str| dir.join("scenes").join(format!("{name}.toml"));
        let mut cases = Vec::new();
        for s in &raw.shader {
            let m = method(&s.reference, &path.display().to_string())?;
            let source = match (&s.pipeline, &s.compute) {
                (Some(p), None) => Source::Pipeline(dir.join(p)),
                (None, Some(c)) => Source::Compute {
                    file: dir.join(c),
                    entry: s.entry.clone().unwrap_or_else(|| "main".into()),
                    cutout_entry: s.cutout_entry.clone(),
                    max_bounces: s.max_bounces.unwrap_or(3),
                },
                _ => {
                    return Err(format!(
                        "{}: shader `{}` needs one of `pipeline` and `compute`",
                        path.display(),
                        s.name
                    ))
                }
            };
            for sc in &s.scenes {
                cases.push(Case {
                    name: format!("{}/{sc}", s.name),
                    shader: s.name.clone(),
                    scene: sc.clone(),
                    kind: CaseKind::Render {
                        source: source.clone(),
                        method: m,
                        scene: scene(sc),
                        extreme: None,
                    },
                });
            }
        }
        for s in &raw.shader {
            for other in s.identical_to.names() {
                let Some(theirs) = raw.shader.iter().find(|o| &o.name == other) else {
                    return Err(format!(
                        "{}: `{}` is to be identical to unknown shader `{other}`",
                        path.display(),
                        s.name
                    ));
                };
                // Only the scenes both render (the WGSL pipelines cannot
                // render cut-outs).
                for sc in s.scenes.iter().filter(|sc| theirs.scenes.contains(sc)) {
                    cases.push(Case {
                        name: format!("{}={other}/{sc}", s.name),
                        shader: format!("{} = {other}", s.name),
                        scene: sc.clone(),
                        kind: CaseKind::Identical {
                            a: format!("{}/{sc}", s.name),
                            b: format!("{other}/{sc}"),
                        },
                    });
                }
            }
        }
        for f in &raw.expected_failure {
            cases.push(Case {
                name: format!("{}/{}", f.name, f.scene),
                shader: f.name.clone(),
                scene: f.scene.clone(),
                kind: CaseKind::ExpectedCrash {
                    source: Source::Pipeline(dir.join(&f.pipeline)),
                    method: method(&f.reference, &path.display().to_string())?,
                    scene: scene(&f.scene),
                    depth: f.max_recursion_depth,
                },
            });
        }
        Ok(Manifest {
            width: raw.width,
            height: raw.height,
            cases,
        })
    }

    /// The numerical-extremes matrix: the `iterative` shader (and `glossy`
    /// for the roughness variants) on the `showcase` scene, every variant
    /// with robust origins and with the fixed epsilon.
    pub fn extremes(&self) -> Vec<Case> {
        let source = |shader: &str| {
            self.cases.iter().find_map(|c| match &c.kind {
                CaseKind::Render {
                    source,
                    method,
                    scene,
                    extreme: None,
                } if c.shader == shader && c.scene == "showcase" => {
                    Some((source.clone(), *method, scene.clone()))
                }
                _ => None,
            })
        };
        let mut cases = Vec::new();
        for variant in EXTREMES {
            let shader = if variant.starts_with("roughness") {
                "glossy"
            } else {
                "iterative"
            };
            let Some((source, method, scene)) = source(shader) else {
                continue;
            };
            for robust in [true, false] {
                let mode = if robust { "robust" } else { "epsilon" };
                cases.push(Case {
                    name: format!("extremes/{variant}/{mode}"),
                    shader: format!("{shader} {mode}"),
                    scene: variant.to_string(),
                    kind: CaseKind::Render {
                        source: source.clone(),
                        method,
                        scene: scene.clone(),
                        extreme: Some(Extreme {
                            variant: variant.to_string(),
                            robust,
                        }),
                    },
                });
            }
        }
        cases
    }

    /// The cases whose name contains `filter`, plus the render cases an
    /// `Identical` case among them needs.
    pub fn select(&self, filter: Option<&str>) -> Vec<Case> {
        let wanted: Vec<&Case> = self
            .cases
            .iter()
            .filter(|c| filter.is_none_or(|f| c.name.contains(f)))
            .collect();
        self.cases
            .iter()
            .filter(|c| {
                wanted.contains(c)
                    || wanted.iter().any(|w| match &w.kind {
                        CaseKind::Identical { a, b } => &c.name == a || &c.name == b,
                        _ => false,
                    })
            })
            .cloned()
            .collect()
    }
}

/// What the CPU and GPU render for a case: the scene and the uniform values.
/// A case's shaders, loaded.
pub enum Loaded {
    Pipeline(Box<crate::pipeline::Pipeline>),
    Compute { words: Vec<u32>, entry: String },
}

pub fn setup(
    manifest: &Manifest,
    source: &Source,
    scene_path: &Path,
    depth: Option<u32>,
) -> Result<(Loaded, Scene, Params), String> {
    let scene = Scene::load(scene_path)?;
    let (loaded, bounces) = match source {
        Source::Pipeline(path) => {
            let mut pipeline = crate::pipeline::load(path)
                .map_err(|e| format!("{}: {}", path.display(), e.0.message.trim_end()))?;
            if depth.is_some() {
                pipeline.max_recursion_depth = depth;
            }
            let bounces = pipeline
                .constant("params.max_bounces")
                .map(|c| c.value)
                .unwrap_or(3);
            let bounces = u32::try_from(bounces)
                .map_err(|_| format!("{}: bad params.max_bounces", path.display()))?;
            (Loaded::Pipeline(Box::new(pipeline)), bounces)
        }
        Source::Compute {
            file,
            entry,
            cutout_entry,
            max_bounces,
        } => {
            let entry = match cutout_entry {
                Some(e) if scene.has_cutouts() => e,
                _ if scene.has_cutouts() => {
                    return Err(format!(
                        "{}: scene {} has cut-outs, and the shader names no `cutout_entry`",
                        file.display(),
                        scene_path.display()
                    ))
                }
                _ => entry,
            };
            let language = crate::shader::Language::from_path(file)
                .ok_or_else(|| format!("{}: not a shader file", file.display()))?;
            let compiled = crate::front::compile_path(file, language)
                .map_err(|e| format!("{}: {}", file.display(), e.0.message.trim_end()))?;
            (
                Loaded::Compute {
                    words: compiled.words,
                    entry: entry.clone(),
                },
                *max_bounces,
            )
        }
    };
    let params = Params::for_scene(&scene, manifest.width, manifest.height, bounces);
    Ok((loaded, scene, params))
}

/// How to run verify.
pub struct Options<'a> {
    pub shaders: PathBuf,
    pub out: PathBuf,
    pub filter: Option<String>,
    /// Also run the numerical-extremes matrix ([`Manifest::extremes`]).
    pub extremes: bool,
    /// Builds the command that runs the named case in a child process (the
    /// child calls [`child_main`] and writes the image to the given file).
    pub child: &'a dyn Fn(&str, &Path) -> Command,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    Pass,
    Fail(String),
    /// An expected failure that did fail as expected.
    ExpectedFailure(String),
    /// The device cannot run the case (ray queries on NVIDIA's driver).
    Skipped(String),
}

/// One row of the verify table.
#[derive(Clone, Debug)]
pub struct Row {
    pub case: Case,
    pub comparison: Option<Comparison>,
    /// Pixels the GPU wrote as non-finite (alpha 0).
    pub nan: Option<usize>,
    /// Rays that hit the triangle they left, per ray that left a surface
    /// (CPU paths), in percent.
    pub self_hit: Option<f64>,
    pub time: Duration,
    pub outcome: Outcome,
    /// What a multi-pass shader measured (paths taken, paths saved).
    pub note: Option<String>,
}

impl Row {
    pub fn passed(&self) -> bool {
        !matches!(self.outcome, Outcome::Fail(_))
    }
}

/// The whole run.
#[derive(Clone, Debug, Default)]
pub struct Report {
    pub device: Option<String>,
    pub rows: Vec<Row>,
}

impl Report {
    pub fn passed(&self) -> bool {
        self.rows.iter().all(Row::passed)
    }
}

/// How a child ended, in words.
fn describe(end: &ChildOutcome) -> String {
    let last = end.stderr.lines().rev().find(|l| !l.trim().is_empty());
    match (end.timed_out, end.signal, end.code) {
        (true, _, _) => format!(
            "the child ran past {} s and was killed",
            CHILD_TIMEOUT.as_secs()
        ),
        (_, Some(s), _) => format!("the child was killed by signal {s} ({})", signal_name(s)),
        (_, _, Some(c)) => match last {
            Some(l) => format!("the child exited with {c}: {}", l.trim()),
            None => format!("the child exited with {c}"),
        },
        _ => "the child ended without a status".into(),
    }
}

fn signal_name(s: i32) -> &'static str {
    match s {
        4 => "SIGILL",
        6 => "SIGABRT",
        7 => "SIGBUS",
        9 => "SIGKILL",
        11 => "SIGSEGV",
        _ => "signal",
    }
}

fn spawn(cmd: Command) -> Result<RunningChild, String> {
    spawn_command(cmd).map_err(|e| format!("cannot start the child process: {e}"))
}

fn wait(r: RunningChild) -> Result<ChildOutcome, String> {
    r.wait(CHILD_TIMEOUT).map_err(|e| e.to_string())
}

fn file_name(case: &str) -> String {
    case.replace(['/', '='], "_")
}

/// Runs the selected cases; `progress` is told before each one starts.
/// An `Err` is a usage or input problem (exit 2); failed cases are rows.
pub fn run(
    options: &Options<'_>,
    mut progress: impl FnMut(usize, usize, &str),
) -> Result<Report, String> {
    let manifest = Manifest::load(&options.shaders)?;
    let mut cases = manifest.select(options.filter.as_deref());
    if options.extremes {
        cases.extend(
            manifest
                .extremes()
                .into_iter()
                .filter(|c| options.filter.as_ref().is_none_or(|f| c.name.contains(f))),
        );
    }
    if cases.is_empty() {
        return Err(match &options.filter {
            Some(f) => format!("no verify case matches `{f}`"),
            None => "the manifest names no case".into(),
        });
    }
    std::fs::create_dir_all(&options.out)
        .map_err(|e| format!("cannot create {}: {e}", options.out.display()))?;
    // Inputs are checked before any GPU work: a bad scene is a usage error.
    for c in &cases {
        if let Some((source, scene, depth)) = c.kind.runs() {
            setup(&manifest, source, scene, depth)?;
        }
    }
    let mut report = Report::default();
    let mut cache = CpuCache::new();
    let mut images: Vec<(String, Vec<u32>)> = Vec::new();
    for (i, case) in cases.iter().enumerate() {
        progress(i, cases.len(), &case.name);
        let start = Instant::now();
        let mut note = None;
        let (comparison, outcome) = match &case.kind {
            CaseKind::Render { .. } => {
                let (c, o, image, n) =
                    render_case(options, &manifest, case, &mut report, &mut cache)?;
                if let Some(image) = image {
                    images.push((case.name.clone(), image));
                }
                note = n;
                (c, o)
            }
            CaseKind::Identical { a, b } => {
                let find = |n: &str| images.iter().find(|(name, _)| name == n).map(|x| &x.1);
                match (find(a), find(b)) {
                    (Some(x), Some(y)) => {
                        let c = compare::compare(x, y, &[], 0);
                        let o = if c.max_diff == 0 {
                            Outcome::Pass
                        } else {
                            Outcome::Fail(format!(
                                "{} pixels of {a} and {b} differ (max {})",
                                c.above, c.max_diff
                            ))
                        };
                        (Some((c, None, None)), o)
                    }
                    _ => {
                        let skipped = report.rows.iter().any(|r| {
                            (&r.case.name == a || &r.case.name == b)
                                && matches!(r.outcome, Outcome::Skipped(_))
                        });
                        let o = if skipped {
                            Outcome::Skipped(format!("{a} or {b} was skipped"))
                        } else {
                            Outcome::Fail(format!("{a} or {b} produced no image"))
                        };
                        (None, o)
                    }
                }
            }
            CaseKind::ExpectedCrash {
                source,
                scene,
                depth,
                ..
            } => {
                let (loaded, _, params) = setup(&manifest, source, scene, Some(*depth))?;
                // What `rtlint check` reports statically (RT021).
                let needs = match &loaded {
                    Loaded::Pipeline(p) => {
                        match crate::analysis::recursion_report(p).required_depth {
                            Some(n) => {
                                format!("rtlint check: needs depth {n}, declared {depth} (RT021)")
                            }
                            None => "rtlint check: recursion depth unbounded (RT024)".into(),
                        }
                    }
                    Loaded::Compute { .. } => "a compute shader has no recursion depth".into(),
                };
                let image = options.out.join(format!("{}.rgba", file_name(&case.name)));
                let end = wait(spawn((options.child)(&case.name, &image))?)?;
                let _ = std::fs::remove_file(&image);
                note_device(&mut report, &end);
                let o = if end.signal.is_some() && !end.timed_out {
                    Outcome::ExpectedFailure(format!("caught: {}; {needs}", describe(&end)))
                } else if end.code == Some(0) && !traps_deep_recursion(report.device.as_deref()) {
                    // Recursing past the declared depth is undefined behaviour:
                    // lavapipe faults, NVIDIA's driver runs on. There the case
                    // shows nothing about catching a crash.
                    Outcome::Skipped(format!(
                        "the pipeline declared with depth {depth} ran clean: this driver does \
                         not fault past the declared depth (undefined behaviour); {needs}"
                    ))
                } else if end.code == Some(0) {
                    Outcome::Fail(format!(
                        "the pipeline declared with depth {depth} ran clean ({}×{}); {needs}",
                        params.width, params.height
                    ))
                } else {
                    Outcome::Fail(format!("expected a crash, but {}", describe(&end)))
                };
                (None, o)
            }
        };
        let (comparison, nan, self_hit) = match comparison {
            Some((c, n, h)) => (Some(c), n, h),
            None => (None, None, None),
        };
        report.rows.push(Row {
            case: case.clone(),
            comparison,
            nan,
            self_hit,
            time: start.elapsed(),
            outcome,
            note,
        });
    }
    progress(cases.len(), cases.len(), "");
    Ok(report)
}

/// Whether the device is one known to kill the process when a pipeline
/// recurses past its declared depth (lavapipe, FIELD-NOTES); an unknown
/// device counts as one, so a clean run there still fails the case.
fn traps_deep_recursion(device: Option<&str>) -> bool {
    match device {
        Some(name) => name.contains("llvmpipe") || !name.to_lowercase().contains("nvidia"),
        None => true,
    }
}

fn note_device(report: &mut Report, end: &ChildOutcome) {
    if report.device.is_none() {
        report.device = end
            .stdout
            .lines()
            .find_map(|l| l.strip_prefix("device: "))
            .map(str::to_string);
    }
}

type Measured = (Comparison, Option<usize>, Option<f64>);
type CaseResult = (Option<Measured>, Outcome, Option<Vec<u32>>, Option<String>);

/// CPU renders by reference method and scene.
type CpuCache = std::collections::HashMap<String, std::rc::Rc<measure::CpuRender>>;

fn render_case(
    options: &Options<'_>,
    manifest: &Manifest,
    case: &Case,
    report: &mut Report,
    cache: &mut CpuCache,
) -> Result<CaseResult, String> {
    let CaseKind::Render {
        source,
        method,
        scene: scene_path,
        extreme,
    } = &case.kind
    else {
        return Err(format!("`{}` is not a render case", case.name));
    };
    let (method, extreme) = (*method, extreme.as_ref());
    let (_, mut scene, mut params) = setup(manifest, source, scene_path, None)?;
    if let Some(e) = extreme {
        e.apply(&mut scene, &mut params)?;
    }
    let image_path = options.out.join(format!("{}.rgba", file_name(&case.name)));
    let _ = std::fs::remove_file(&image_path);
    // The CPU reference renders while the child runs.
    let running = spawn((options.child)(&case.name, &image_path))?;
    // The CPU render of a case that is not an extreme is shared by every
    // shader with the same reference and scene.
    let key = format!("{method:?} {}", scene_path.display());
    let cpu_render = match cache.get(&key) {
        Some(r) if extreme.is_none() => r.clone(),
        _ => {
            let r = std::rc::Rc::new(measure::cpu_render(&scene, &params, method));
            if extreme.is_none() {
                cache.insert(key, r.clone());
            }
            r
        }
    };
    let (cpu, margins) = (&cpu_render.image, &cpu_render.margins);
    let end = wait(running)?;
    note_device(report, &end);
    if end.code == Some(SKIP_CODE) {
        let why = end
            .stdout
            .lines()
            .find_map(|l| l.strip_prefix("skip: "))
            .unwrap_or("the device cannot run it");
        return Ok((None, Outcome::Skipped(why.to_string()), None, None));
    }
    if end.code != Some(0) {
        return Ok((None, Outcome::Fail(describe(&end)), None, None));
    }
    let gpu = read_words(&image_path)?;
    let gpu_counts = if method.scratch() {
        Some(read_words(&counts_path(&image_path))?)
    } else {
        None
    };
    if gpu.len() != cpu.len() {
        return Ok((
            None,
            Outcome::Fail(format!(
                "the child wrote {} pixels, not {}",
                gpu.len(),
                cpu.len()
            )),
            None,
            None,
        ));
    }
    let c = compare::compare(&gpu, cpu, margins, TOLERANCE);
    let base = options.out.join(file_name(&case.name));
    let png = |suffix: &str, image: &[u32]| {
        compare::write_png(
            &PathBuf::from(format!("{}-{suffix}.png", base.display())),
            image,
            params.width,
            params.height,
        )
    };
    // The GPU image always; the CPU image and the difference on failure.
    png("gpu", &gpu)?;
    let nan = gpu.iter().filter(|&&p| p >> 24 == 0).count();
    if let Some(e) = extreme {
        // The matrix: no NaN or infinity ever; with robust origins fewer
        // than 0.1 % of the rays leaving a surface hit it again. The
        // difference to the CPU is reported, not judged (far from the
        // origin both sides round differently by design).
        // The CPU's colours are checked in f32 too, before any packing.
        let (mut own, mut secondary, mut cpu_nan) = (0usize, 0usize, 0usize);
        for y in 0..params.height {
            for x in 0..params.width {
                let path = reference::trace_pixel(&scene, &params, method, x, y);
                let (o, n) = path.self_hits();
                own += o;
                secondary += n;
                cpu_nan += usize::from(!path.color.is_finite());
            }
        }
        let rate = 100.0 * own as f64 / secondary.max(1) as f64;
        let outcome = if nan > 0 || cpu_nan > 0 {
            Outcome::Fail(format!(
                "{nan} GPU and {cpu_nan} CPU pixels are NaN or infinite"
            ))
        } else if e.robust && rate >= 0.1 {
            Outcome::Fail(format!(
                "{own} of {secondary} rays ({rate:.3} %) hit the triangle they left"
            ))
        } else {
            Outcome::Pass
        };
        return Ok((Some((c, Some(nan), Some(rate))), outcome, Some(gpu), None));
    }
    // Multi-pass shaders: their per-pixel counts against the CPU's, and
    // what they measured.
    let mut counts_ok = true;
    let note = match (&gpu_counts, &cpu_render.counts) {
        (Some(g), Some(k)) if g.len() == k.len() => {
            let differ = g.iter().zip(k).filter(|(a, b)| a != b).count();
            counts_ok = differ * 1000 <= g.len();
            let m = measure::measure(&cpu_render, g, differ);
            if let Some(picture) = &m.picture {
                png("paths", picture)?;
            }
            Some(m.note)
        }
        (Some(_), _) => {
            counts_ok = false;
            Some("the child's counts do not cover the image".into())
        }
        _ => None,
    };
    let outcome = if c.passes() && nan == 0 && counts_ok {
        Outcome::Pass
    } else if !counts_ok {
        Outcome::Fail(format!(
            "more than 0.1 % of the per-pixel counts differ from the CPU's: {}",
            note.as_deref().unwrap_or("")
        ))
    } else {
        png("cpu", cpu)?;
        png("diff", &compare::difference(&gpu, cpu))?;
        Outcome::Fail(format!(
            "{} pixels above {TOLERANCE}/255 ({} near an edge); images in {}",
            c.above,
            c.near_edge,
            options.out.display()
        ))
    };
    Ok((Some((c, Some(nan), None)), outcome, Some(gpu), note))
}

/// The child's side: renders case `name` on the device and writes the
/// packed image to `image`. Prints `device: NAME` and `trace: MS` on stdout.
pub fn child_main(
    shaders: &Path,
    name: &str,
    image: &Path,
    device: Option<&str>,
) -> Result<(), String> {
    let manifest = Manifest::load(shaders)?;
    let extremes = manifest.extremes();
    let case = manifest
        .cases
        .iter()
        .chain(&extremes)
        .find(|c| c.name == name)
        .ok_or_else(|| format!("no verify case `{name}`"))?;
    let Some((source, scene_path, depth)) = case.kind.runs() else {
        return Err(format!("`{name}` runs nothing"));
    };
    let (loaded, mut scene, mut params) = setup(&manifest, source, scene_path, depth)?;
    if let CaseKind::Render {
        extreme: Some(e), ..
    } = &case.kind
    {
        e.apply(&mut scene, &mut params)?;
    }
    let ctx = crate::vk::Context::with_options(&crate::vk::ContextOptions {
        device_name: device.map(str::to_string),
        ..Default::default()
    })
    .map_err(|e| e.to_string())?;
    println!("device: {}", ctx.info().name);
    let method = match &case.kind {
        CaseKind::Render { method, .. } | CaseKind::ExpectedCrash { method, .. } => *method,
        CaseKind::Identical { .. } => Method::Iterative,
    };
    let rendered = match &loaded {
        Loaded::Pipeline(p) => gpu::render_passes(
            &ctx,
            p,
            None,
            &scene,
            &params,
            gpu::Passes::for_method(method, &params),
        )?,
        Loaded::Compute { words, entry } => {
            if !ctx.info().ray_query {
                println!("skip: {} has no VK_KHR_ray_query", ctx.info().name);
                return Err(SKIP.into());
            }
            gpu::render_compute(&ctx, words, entry, &scene, &params)?
        }
    };
    println!("trace: {:.3}", rendered.trace.as_secs_f64() * 1000.0);
    println!("total: {:.3}", rendered.total.as_secs_f64() * 1000.0);
    let write = |path: &Path, words: &[u32]| {
        let bytes: Vec<u8> = words.iter().flat_map(|p| p.to_le_bytes()).collect();
        std::fs::write(path, bytes).map_err(|e| format!("cannot write {}: {e}", path.display()))
    };
    if let Some(counts) = &rendered.counts {
        write(&counts_path(image), counts)?;
    }
    write(image, &rendered.image)
}

/// Where the child writes the per-pixel counts of a multi-pass shader.
fn counts_path(image: &Path) -> PathBuf {
    image.with_extension("counts")
}

fn read_words(path: &Path) -> Result<Vec<u32>, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let _ = std::fs::remove_file(path);
    Ok(bytes
        .chunks_exact(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect())
}

/// The table's columns, in order.
pub const COLUMNS: [&str; 10] = [
    "shader",
    "case",
    "pixels",
    "max diff",
    "mean diff",
    "above tol",
    "PSNR dB",
    "NaN",
    "self-hit %",
    "time",
];

impl Row {
    /// The row's cells under [`COLUMNS`], then the verdict.
    pub fn cells(&self) -> Vec<String> {
        let c = self.comparison.as_ref();
        let or_dash = |v: Option<String>| v.unwrap_or_else(|| "-".into());
        vec![
            self.case.shader.clone(),
            self.case.scene.clone(),
            or_dash(c.map(|c| c.pixels.to_string())),
            or_dash(c.map(|c| c.max_diff.to_string())),
            or_dash(c.map(|c| format!("{:.4}", c.mean_diff))),
            or_dash(c.map(|c| c.above.to_string())),
            or_dash(c.map(|c| {
                if c.psnr.is_infinite() {
                    "inf".into()
                } else {
                    format!("{:.1}", c.psnr)
                }
            })),
            or_dash(self.nan.map(|n| n.to_string())),
            or_dash(self.self_hit.map(|h| format!("{h:.3}"))),
            format!("{:.0} ms", self.time.as_secs_f64() * 1000.0),
            match &self.outcome {
                Outcome::Pass => "pass".into(),
                Outcome::Fail(_) => "FAIL".into(),
                Outcome::ExpectedFailure(_) => "pass (expected failure)".into(),
                Outcome::Skipped(_) => "skipped".into(),
            },
        ]
    }
}

/// Rows of cells as text in left-aligned columns two spaces apart (the
/// tables `verify` and `tradeoff` print).
pub(crate) fn aligned(rows: &[Vec<String>]) -> String {
    let columns = rows.iter().map(Vec::len).max().unwrap_or(0);
    let widths: Vec<usize> = (0..columns)
        .map(|k| {
            rows.iter()
                .filter_map(|r| r.get(k))
                .map(|c| c.chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut out = String::new();
    for r in rows {
        let line: Vec<String> = r
            .iter()
            .zip(&widths)
            .map(|(c, w)| format!("{c:<w$}"))
            .collect();
        out.push_str(line.join("  ").trim_end());
        out.push('\n');
    }
    out
}

impl Report {
    /// The table as aligned text, one line per case, then the reasons of
    /// failures and expected failures.
    pub fn text(&self) -> String {
        let mut rows: Vec<Vec<String>> = vec![COLUMNS
            .iter()
            .map(|s| s.to_string())
            .chain(["result".to_string()])
            .collect()];
        rows.extend(self.rows.iter().map(Row::cells));
        let mut out = aligned(&rows);
        for r in &self.rows {
            match &r.outcome {
                Outcome::Fail(why) => out.push_str(&format!("FAIL {}: {why}\n", r.case.name)),
                Outcome::ExpectedFailure(why) => {
                    out.push_str(&format!("expected failure {}: {why}\n", r.case.name))
                }
                Outcome::Skipped(why) => out.push_str(&format!("skipped {}: {why}\n", r.case.name)),
                Outcome::Pass => {}
            }
        }
        for r in &self.rows {
            if let Some(note) = &r.note {
                out.push_str(&format!("{}: {note}\n", r.case.name));
            }
        }
        out
    }

    pub fn csv(&self) -> String {
        let mut out = COLUMNS.join(",") + ",result\n";
        for r in &self.rows {
            out.push_str(&r.cells().join(","));
            out.push('\n');
        }
        out
    }

    pub fn markdown(&self) -> String {
        let mut out = format!("| {} | result |\n", COLUMNS.join(" | "));
        out.push_str(&"| --- ".repeat(COLUMNS.len() + 1));
        out.push_str("|\n");
        for r in &self.rows {
            out.push_str(&format!("| {} |\n", r.cells().join(" | ")));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shaders() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders")
    }

    #[test]
    fn a_clean_run_past_the_depth_fails_only_where_the_driver_traps() {
        assert!(traps_deep_recursion(Some(
            "llvmpipe (LLVM 15.0.6, 256 bits)"
        )));
        assert!(traps_deep_recursion(None));
        assert!(traps_deep_recursion(Some("Some Other GPU")));
        assert!(!traps_deep_recursion(Some("NVIDIA H200")));
    }

    #[test]
    fn the_bundled_manifest_resolves() {
        let m = Manifest::load(&shaders()).unwrap();
        let names: Vec<&str> = m.cases.iter().map(|c| c.name.as_str()).collect();
        assert!(names.contains(&"iterative/mirror"), "{names:?}");
        assert!(names.contains(&"recursive=iterative/showcase"), "{names:?}");
        assert!(m
            .cases
            .iter()
            .any(|c| matches!(c.kind, CaseKind::ExpectedCrash { .. })));
        for c in &m.cases {
            if let Some((source, scene, depth)) = c.kind.runs() {
                setup(&m, source, scene, depth).unwrap();
            }
        }
        // Ray-query shaders run their cut-out entry point only on scenes
        // with cut-outs.
        for (case, want) in [
            ("rayquery/mirror", "main"),
            ("rayquery-hlsl/cutout", "main_alpha"),
        ] {
            let c = m.cases.iter().find(|c| c.name == case).unwrap();
            let (source, scene, depth) = c.kind.runs().unwrap();
            match setup(&m, source, scene, depth).unwrap().0 {
                Loaded::Compute { entry, .. } => assert_eq!(entry, want),
                Loaded::Pipeline(_) => panic!("{case} is a compute case"),
            }
        }
        // Selecting an identity case brings the renders it compares.
        let sel = m.select(Some("recursive=iterative/mirror"));
        let names: Vec<&str> = sel.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "iterative/mirror",
                "recursive/mirror",
                "recursive=iterative/mirror"
            ]
        );
    }
}
