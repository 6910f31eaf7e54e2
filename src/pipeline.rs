//! The pipeline description (`*.pipeline.toml`): which shaders, groups and
//! depth a scene really uses, so recursion and stack size are computed for
//! that pipeline rather than for every shader in a folder. See
//! `docs/pipeline.md` for the format. An HLSL library that no description
//! names may describe its pipeline itself with DXR subobjects
//! ([`Pipeline::from_subobjects`]).

use crate::diag::{InputError, InputErrorKind, Location};
use crate::front;
use crate::front::hlsl::subobject::Subobjects;
use crate::program::{Id, Program};
use crate::shader::Language;
use crate::shader::Stage;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// The recursion limit of lavapipe, NVIDIA and DXR.
pub const DEFAULT_DEVICE_MAX_RECURSION_DEPTH: u32 = 31;

/// Where a shader sits in the pipeline.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case", tag = "slot", content = "index")]
pub enum Slot {
    Raygen(usize),
    Miss(usize),
    /// Hit group index; the node's stage says which shader of the group.
    HitGroup(usize),
    Callable(usize),
}

impl std::fmt::Display for Slot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Slot::Raygen(i) => write!(f, "raygen {i}"),
            Slot::Miss(i) => write!(f, "miss {i}"),
            Slot::HitGroup(i) => write!(f, "hit group {i}"),
            Slot::Callable(i) => write!(f, "callable {i}"),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum HitGroupKind {
    Triangles,
    Procedural,
}

/// One shader of the pipeline: an entry point in a loaded program.
#[derive(Clone, Debug)]
pub struct ShaderRef {
    /// Index into [`Pipeline::programs`].
    pub program: usize,
    pub entry: String,
    pub function: Id,
    pub stage: Stage,
    pub file: PathBuf,
    /// Where the description names it; `None` without a description.
    pub location: Option<Location>,
}

#[derive(Clone, Debug)]
pub struct HitGroup {
    pub kind: HitGroupKind,
    pub closest_hit: Option<ShaderRef>,
    pub any_hit: Option<ShaderRef>,
    pub intersection: Option<ShaderRef>,
    pub location: Option<Location>,
}

impl HitGroup {
    pub fn shaders(&self) -> impl Iterator<Item = &ShaderRef> {
        [&self.closest_hit, &self.any_hit, &self.intersection]
            .into_iter()
            .flatten()
    }
}

/// A number a DXR subobject declares, with the declaration.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Declared {
    pub value: u32,
    pub location: Location,
}

/// A value from `[constants]`, with the line that set it.
#[derive(Clone, Debug)]
pub struct DescribedConstant {
    pub value: i64,
    pub location: Option<Location>,
}

#[derive(Debug)]
pub struct Pipeline {
    /// The description file, or `None` when built from loose shaders.
    pub path: Option<PathBuf>,
    /// `maxPipelineRayRecursionDepth` as the application declares it.
    pub max_recursion_depth: Option<u32>,
    pub max_recursion_depth_location: Option<Location>,
    pub all_geometry_opaque: bool,
    /// `instanceShaderBindingTableRecordOffset` of every instance.
    pub instance_sbt_offsets: Vec<u32>,
    /// Geometries per bottom-level structure (the SBT stride multiplies it).
    pub geometries_per_instance: u32,
    pub device_max_recursion_depth: u32,
    /// Push / specialization constant values by name (`block.member`,
    /// `member`, or a specialization constant's name).
    pub constants: BTreeMap<String, DescribedConstant>,
    pub programs: Vec<Program>,
    pub raygen: Vec<ShaderRef>,
    pub miss: Vec<ShaderRef>,
    pub hit_groups: Vec<HitGroup>,
    pub callable: Vec<ShaderRef>,
    /// The HLSL library whose DXR subobjects describe this pipeline, when
    /// no `*.pipeline.toml` does. They name the shaders, hit groups and
    /// depth but not the shader table's order.
    pub subobject_library: Option<PathBuf>,
    /// `RaytracingPipelineConfig` depths the pipeline's HLSL files declare.
    pub subobject_depths: Vec<Declared>,
    /// `RaytracingShaderConfig` maximum payload and attribute sizes.
    pub max_payload_bytes: Option<Declared>,
    pub max_attribute_bytes: Option<Declared>,
}

impl Pipeline {
    /// The file findings about the whole pipeline point at: the description,
    /// else the first ray-generation shader's file.
    pub fn file(&self) -> PathBuf {
        self.path
            .clone()
            .or_else(|| self.raygen.first().map(|s| s.file.clone()))
            .unwrap_or_default()
    }

    /// Whether a description says which shaders the scene uses.
    pub fn described(&self) -> bool {
        self.path.is_some()
    }

    /// Every shader, raygen first, then miss, hit groups, callables.
    pub fn shaders(&self) -> impl Iterator<Item = &ShaderRef> {
        self.raygen
            .iter()
            .chain(self.miss.iter())
            .chain(self.hit_groups.iter().flat_map(|g| g.shaders()))
            .chain(self.callable.iter())
    }

    pub fn program(&self, s: &ShaderRef) -> Option<&Program> {
        self.programs.get(s.program)
    }

    pub fn constant(&self, name: &str) -> Option<&DescribedConstant> {
        self.constants.get(name)
    }

    /// The conservative pipeline for shaders without a description: every
    /// ray-tracing entry point is in it, each hit shader in a group of its
    /// own, and every trace may reach every group and miss shader.
    pub fn from_programs(programs: Vec<Program>) -> Pipeline {
        let mut p = Pipeline {
            path: None,
            max_recursion_depth: None,
            max_recursion_depth_location: None,
            all_geometry_opaque: false,
            instance_sbt_offsets: vec![0],
            geometries_per_instance: 1,
            device_max_recursion_depth: DEFAULT_DEVICE_MAX_RECURSION_DEPTH,
            constants: BTreeMap::new(),
            programs: Vec::new(),
            raygen: Vec::new(),
            miss: Vec::new(),
            hit_groups: Vec::new(),
            callable: Vec::new(),
            subobject_library: None,
            subobject_depths: Vec::new(),
            max_payload_bytes: None,
            max_attribute_bytes: None,
        };
        for (i, program) in programs.iter().enumerate() {
            for e in &program.entry_points {
                let s = ShaderRef {
                    program: i,
                    entry: e.name.clone(),
                    function: e.function,
                    stage: e.stage,
                    file: program.path.clone(),
                    location: None,
                };
                let group = |kind, s: ShaderRef| {
                    let mut g = HitGroup {
                        kind,
                        closest_hit: None,
                        any_hit: None,
                        intersection: None,
                        location: None,
                    };
                    match s.stage {
                        Stage::ClosestHit => g.closest_hit = Some(s),
                        Stage::AnyHit => g.any_hit = Some(s),
                        _ => g.intersection = Some(s),
                    }
                    g
                };
                match e.stage {
                    Stage::RayGeneration => p.raygen.push(s),
                    Stage::Miss => p.miss.push(s),
                    Stage::Callable => p.callable.push(s),
                    Stage::ClosestHit | Stage::AnyHit => {
                        p.hit_groups.push(group(HitGroupKind::Triangles, s))
                    }
                    Stage::Intersection => p.hit_groups.push(group(HitGroupKind::Procedural, s)),
                    _ => {}
                }
            }
        }
        p.programs = programs;
        p
    }

    /// Whether `subobjects` describe a pipeline around `program`: it has a
    /// ray generation shader and they hold a pipeline config, a shader
    /// config or a hit group. ([`Pipeline::from_subobjects`] can still
    /// refuse: a hit group may name a shader of another library.)
    pub fn subobjects_describe(program: &Program, subobjects: &Subobjects) -> bool {
        let describes = !subobjects.pipeline_configs.is_empty()
            || !subobjects.shader_configs.is_empty()
            || !subobjects.hit_groups.is_empty();
        describes
            && program
                .entry_points
                .iter()
                .any(|e| e.stage == Stage::RayGeneration)
    }

    /// The pipeline an HLSL library describes with DXR subobjects: its
    /// ray generation, miss and callable shaders (`[shader("...")]`), the
    /// hit groups it declares (each hit shader in a group of its own when it
    /// declares none), the depth of `RaytracingPipelineConfig` and the sizes
    /// of `RaytracingShaderConfig`. `None` when the subobjects describe no
    /// pipeline (no pipeline config, shader config or hit group, or no ray
    /// generation shader) or a hit group names a shader the library does not
    /// define with that stage (it is linked from another library): then the
    /// program comes back.
    pub fn from_subobjects(
        program: Program,
        subobjects: &Subobjects,
    ) -> Result<Pipeline, Box<Program>> {
        if !Pipeline::subobjects_describe(&program, subobjects) {
            return Err(Box::new(program));
        }
        let file = program.path.clone();
        let mut p = Pipeline::from_programs(vec![program]);
        if !subobjects.hit_groups.is_empty() {
            let program = &p.programs[0];
            let find = |name: &Option<String>, stage: Stage, at: &Location| {
                let Some(name) = name else {
                    return Some(None);
                };
                let e = program
                    .entry_points
                    .iter()
                    .find(|e| e.name == *name && e.stage == stage)?;
                Some(Some(ShaderRef {
                    program: 0,
                    entry: e.name.clone(),
                    function: e.function,
                    stage,
                    file: file.clone(),
                    location: Some(at.clone()),
                }))
            };
            let group = |g: &front::hlsl::subobject::HitGroup| {
                let at = &g.location;
                Some(HitGroup {
                    kind: if g.procedural {
                        HitGroupKind::Procedural
                    } else {
                        HitGroupKind::Triangles
                    },
                    closest_hit: find(&g.closest_hit, Stage::ClosestHit, at)?,
                    any_hit: find(&g.any_hit, Stage::AnyHit, at)?,
                    intersection: find(&g.intersection, Stage::Intersection, at)?,
                    location: Some(at.clone()),
                })
            };
            match subobjects.hit_groups.iter().map(group).collect() {
                Some(groups) => p.hit_groups = groups,
                None => return Err(Box::new(p.programs.remove(0))),
            }
        }
        if let Some(c) = subobjects
            .pipeline_configs
            .iter()
            .max_by_key(|c| c.max_recursion_depth)
        {
            p.max_recursion_depth = Some(c.max_recursion_depth);
            p.max_recursion_depth_location = Some(c.location.clone());
        }
        p.add_subobjects(subobjects);
        p.subobject_library = Some(file);
        Ok(p)
    }

    /// Records the depths and sizes a library's subobjects declare.
    fn add_subobjects(&mut self, subobjects: &Subobjects) {
        self.subobject_depths
            .extend(subobjects.pipeline_configs.iter().map(|c| Declared {
                value: c.max_recursion_depth,
                location: c.location.clone(),
            }));
        let largest = |v: Option<Declared>, value: u32, location: &Location| match v {
            Some(d) if d.value >= value => Some(d),
            _ => Some(Declared {
                value,
                location: location.clone(),
            }),
        };
        for c in &subobjects.shader_configs {
            self.max_payload_bytes = largest(
                self.max_payload_bytes.take(),
                c.max_payload_bytes,
                &c.location,
            );
            self.max_attribute_bytes = largest(
                self.max_attribute_bytes.take(),
                c.max_attribute_bytes,
                &c.location,
            );
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPipeline {
    max_recursion_depth: Option<Spanned<i64>>,
    all_geometry_opaque: Option<bool>,
    instance_sbt_offsets: Option<Vec<Spanned<i64>>>,
    geometries_per_instance: Option<Spanned<i64>>,
    device_max_recursion_depth: Option<Spanned<i64>>,
    #[serde(default)]
    raygen: Vec<Spanned<RawShader>>,
    #[serde(default)]
    miss: Vec<Spanned<RawShader>>,
    #[serde(default)]
    hit_group: Vec<Spanned<RawHitGroup>>,
    #[serde(default)]
    callable: Vec<Spanned<RawShader>>,
    #[serde(default)]
    constants: BTreeMap<String, Spanned<toml::Value>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawShader {
    file: Spanned<String>,
    entry: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHitGroup {
    #[serde(rename = "type")]
    kind: Option<Spanned<String>>,
    closest_hit: Option<Spanned<RawShader>>,
    any_hit: Option<Spanned<RawShader>>,
    intersection: Option<Spanned<RawShader>>,
}

/// Reads a description and loads every shader it names.
pub fn load(path: &Path) -> Result<Pipeline, InputError> {
    load_with(path, &front::FrontOptions::default())
}

/// [`load`], compiling the shaders with `options` (include directories,
/// defines), as every other input of the run is.
pub fn load_with(path: &Path, options: &front::FrontOptions) -> Result<Pipeline, InputError> {
    let text = front::read_text(path)?;
    parse_with(&text, path, options)
}

/// Parses a description; shader files are relative to `path`'s folder.
pub fn parse(text: &str, path: &Path) -> Result<Pipeline, InputError> {
    parse_with(text, path, &front::FrontOptions::default())
}

/// [`parse`], compiling the shaders with `options`.
pub fn parse_with(
    text: &str,
    path: &Path,
    options: &front::FrontOptions,
) -> Result<Pipeline, InputError> {
    let cx = Cx {
        text,
        path,
        options,
    };
    let raw: RawPipeline = toml::from_str(text).map_err(|e| {
        let err = InputError::new(
            InputErrorKind::InvalidPipeline,
            path,
            format!("invalid pipeline description: {}", e.message().trim_end()),
        );
        match e.span() {
            Some(span) => err.at(cx.loc(span), "here"),
            None => err,
        }
    })?;
    let mut p = Pipeline::from_programs(Vec::new());
    p.path = Some(path.to_path_buf());
    if let Some(d) = &raw.max_recursion_depth {
        p.max_recursion_depth = Some(cx.u32(d, "max_recursion_depth")?);
        p.max_recursion_depth_location = Some(cx.loc(d.span()));
    }
    p.all_geometry_opaque = raw.all_geometry_opaque.unwrap_or(false);
    if let Some(offsets) = &raw.instance_sbt_offsets {
        p.instance_sbt_offsets = offsets
            .iter()
            .map(|o| cx.u32(o, "instance_sbt_offsets"))
            .collect::<Result<_, _>>()?;
    }
    if let Some(g) = &raw.geometries_per_instance {
        p.geometries_per_instance = cx.u32(g, "geometries_per_instance")?.max(1);
    }
    if let Some(d) = &raw.device_max_recursion_depth {
        p.device_max_recursion_depth = cx.u32(d, "device_max_recursion_depth")?;
    }
    for (name, v) in &raw.constants {
        let value = match v.get_ref() {
            toml::Value::Integer(i) => *i,
            toml::Value::Boolean(b) => i64::from(*b),
            other => {
                return Err(cx.error(
                    v.span(),
                    format!(
                        "constant `{name}` must be an integer, found {}",
                        other.type_str()
                    ),
                ))
            }
        };
        p.constants.insert(
            name.clone(),
            DescribedConstant {
                value,
                location: Some(cx.loc(v.span())),
            },
        );
    }
    if raw.raygen.is_empty() {
        return Err(InputError::new(
            InputErrorKind::InvalidPipeline,
            path,
            "pipeline description has no `[[raygen]]` shader",
        ));
    }
    let mut loader = Loader {
        cx: &cx,
        programs: Vec::new(),
        subobjects: Vec::new(),
    };
    for s in &raw.raygen {
        p.raygen.push(loader.shader(s, Stage::RayGeneration)?);
    }
    for s in &raw.miss {
        p.miss.push(loader.shader(s, Stage::Miss)?);
    }
    for s in &raw.callable {
        p.callable.push(loader.shader(s, Stage::Callable)?);
    }
    for g in &raw.hit_group {
        let r = g.get_ref();
        let kind = match r.kind.as_ref().map(|k| (k.get_ref().as_str(), k.span())) {
            None | Some(("triangles", _)) => HitGroupKind::Triangles,
            Some(("procedural", _)) => HitGroupKind::Procedural,
            Some((other, span)) => {
                return Err(cx.error(
                    span,
                    format!(
                        "unknown hit group type `{other}`: expected `triangles` or `procedural`"
                    ),
                ))
            }
        };
        let mut shader = |s: &Option<Spanned<RawShader>>, stage| {
            s.as_ref().map(|s| loader.shader(s, stage)).transpose()
        };
        let group = HitGroup {
            kind,
            closest_hit: shader(&r.closest_hit, Stage::ClosestHit)?,
            any_hit: shader(&r.any_hit, Stage::AnyHit)?,
            intersection: shader(&r.intersection, Stage::Intersection)?,
            location: Some(cx.loc(g.span())),
        };
        match (kind, &group.intersection) {
            (HitGroupKind::Procedural, None) => {
                return Err(cx.error(
                    g.span(),
                    "a procedural hit group needs an `intersection` shader",
                ))
            }
            (HitGroupKind::Triangles, Some(_)) => {
                return Err(cx.error(
                    g.span(),
                    "a triangles hit group cannot have an `intersection` shader: set `type = \"procedural\"`",
                ))
            }
            _ => {}
        }
        p.hit_groups.push(group);
    }
    for s in &loader.subobjects {
        p.add_subobjects(s);
    }
    p.programs = loader.programs;
    Ok(p)
}

struct Cx<'a> {
    text: &'a str,
    path: &'a Path,
    /// How the shaders it names are compiled.
    options: &'a front::FrontOptions,
}

impl Cx<'_> {
    fn loc(&self, span: Range<usize>) -> Location {
        let start = span.start.min(self.text.len());
        let before = self.text.get(..start).unwrap_or("");
        let line = before.matches('\n').count() as u32 + 1;
        let col = before
            .rfind('\n')
            .map_or(before.chars().count(), |i| before[i + 1..].chars().count())
            as u32
            + 1;
        // Keep a multi-line span (a table) to its first line.
        let first = self
            .text
            .get(start..span.end.min(self.text.len()))
            .unwrap_or("")
            .lines()
            .next()
            .unwrap_or("");
        Location::span(self.path, line, col, first.chars().count().max(1) as u32)
    }

    fn error(&self, span: Range<usize>, msg: impl Into<String>) -> InputError {
        InputError::new(InputErrorKind::InvalidPipeline, self.path, msg).at(self.loc(span), "here")
    }

    fn u32(&self, v: &Spanned<i64>, key: &str) -> Result<u32, InputError> {
        u32::try_from(*v.get_ref()).map_err(|_| {
            self.error(
                v.span(),
                format!("`{key}` must be between 0 and {}", u32::MAX),
            )
        })
    }
}

struct Loader<'a> {
    cx: &'a Cx<'a>,
    programs: Vec<Program>,
    /// DXR subobjects of the HLSL files loaded.
    subobjects: Vec<Subobjects>,
}

impl Loader<'_> {
    fn shader(&mut self, raw: &Spanned<RawShader>, stage: Stage) -> Result<ShaderRef, InputError> {
        let cx = self.cx;
        let r = raw.get_ref();
        let dir = cx.path.parent().unwrap_or(Path::new(""));
        let file = crate::program::debug::normalize(&dir.join(r.file.get_ref()));
        let here = cx.loc(r.file.span());
        let lang = Language::from_path(&file).ok_or_else(|| {
            cx.error(
                r.file.span(),
                format!(
                    "cannot tell the language of `{}`: expected .wgsl, .hlsl or .spv",
                    r.file.get_ref()
                ),
            )
        })?;
        if !file.is_file() {
            return Err(cx.error(
                r.file.span(),
                format!("shader file `{}` does not exist", file.display()),
            ));
        }
        let index = match self.programs.iter().position(|p| p.path == file) {
            Some(i) => i,
            None => {
                let (program, subobjects) = front::load_library(&file, None, lang, cx.options)
                    .map_err(|e| {
                        e.with_note(format!(
                            "the pipeline description names this file at {here}"
                        ))
                    })?;
                self.programs.push(program);
                self.subobjects.push(subobjects);
                self.programs.len() - 1
            }
        };
        let program = &self.programs[index];
        let entry = match &r.entry {
            Some(name) => {
                let Some(e) = program
                    .entry_points
                    .iter()
                    .find(|e| e.name == *name.get_ref())
                else {
                    let known: Vec<String> = program
                        .entry_points
                        .iter()
                        .map(|e| format!("`{}` ({})", e.name, e.stage.as_str()))
                        .collect();
                    return Err(cx
                        .error(
                            name.span(),
                            format!(
                                "`{}` has no entry point `{}`",
                                file.display(),
                                name.get_ref()
                            ),
                        )
                        .with_note(format!("entry points: {}", known.join(", "))));
                };
                if e.stage != stage {
                    return Err(cx.error(
                        name.span(),
                        format!(
                            "entry point `{}` is a {} shader, listed as a {} shader",
                            e.name,
                            e.stage.as_str(),
                            stage.as_str()
                        ),
                    ));
                }
                e
            }
            None => {
                let mut of_stage = program.entry_points.iter().filter(|e| e.stage == stage);
                match (of_stage.next(), of_stage.next()) {
                    (Some(e), None) => e,
                    _ => {
                        return Err(cx.error(
                            raw.span(),
                            format!(
                                "`{}` needs `entry`: it has no single {} entry point",
                                file.display(),
                                stage.as_str()
                            ),
                        ))
                    }
                }
            }
        };
        Ok(ShaderRef {
            program: index,
            entry: entry.name.clone(),
            function: entry.function,
            stage,
            file,
            location: Some(cx.loc(raw.span())),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/pipelines")
    }

    fn bad(text: &str) -> (String, u32, u32) {
        let e = parse(text, &dir().join("t.pipeline.toml")).unwrap_err();
        let d = e.diagnostic();
        let p = d.primary.as_ref().expect("an error points into the TOML");
        (d.message.clone(), p.location.line, p.location.column)
    }

    #[test]
    fn loads_the_recursive_pipeline() {
        let p = load(&dir().join("reflect_recursive.pipeline.toml")).unwrap();
        assert_eq!(p.max_recursion_depth, Some(5));
        assert_eq!(p.raygen.len(), 1);
        assert_eq!(p.miss.len(), 2);
        assert_eq!(p.hit_groups.len(), 1);
        assert_eq!(p.programs.len(), 4);
        assert_eq!(p.constant("pushConst.maxDepth").unwrap().value, 3);
        assert_eq!(
            p.hit_groups[0].closest_hit.as_ref().unwrap().stage,
            Stage::ClosestHit
        );
        assert_eq!(p.max_recursion_depth_location.as_ref().unwrap().line, 3);
    }

    #[test]
    fn one_wgsl_file_is_loaded_once() {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders/reflect_iterative.pipeline.toml");
        let p = load(&path).unwrap();
        assert_eq!(p.programs.len(), 1);
        assert_eq!(p.shaders().count(), 3);
    }

    const HEAD: &str = "max_recursion_depth = 1\n[[raygen]]\n";

    #[test]
    fn unknown_entry_point() {
        let (msg, line, col) = bad(&format!(
            "{HEAD}file = \"recursive/reflect.rgen.spv\"\nentry = \"mian\"\n"
        ));
        assert!(msg.contains("no entry point `mian`"), "{msg}");
        assert_eq!((line, col), (4, 9));
    }

    #[test]
    fn stage_mismatch() {
        let (msg, line, _) = bad(&format!(
            "{HEAD}file = \"recursive/reflect.rmiss.spv\"\nentry = \"main\"\n"
        ));
        assert_eq!(
            msg,
            "entry point `main` is a miss shader, listed as a raygeneration shader"
        );
        assert_eq!(line, 4);
    }

    #[test]
    fn missing_file() {
        let (msg, line, col) = bad(&format!("{HEAD}file = \"nope.spv\"\n"));
        assert!(msg.contains("does not exist"), "{msg}");
        assert_eq!((line, col), (3, 8));
    }

    #[test]
    fn wrong_type_and_unknown_key() {
        let (msg, line, _) = bad("max_recursion_depth = \"two\"\n");
        assert!(msg.starts_with("invalid pipeline description"), "{msg}");
        assert_eq!(line, 1);
        let (msg, line, _) = bad("max_recursion_depth = 1\nmax_depth = 2\n");
        assert!(msg.contains("unknown field `max_depth`"), "{msg}");
        assert_eq!(line, 2);
        let (msg, line, _) = bad("max_recursion_depth = -1\n");
        assert!(msg.contains("between 0 and"), "{msg}");
        assert_eq!(line, 1);
        let (msg, _, _) = bad(&format!(
            "{HEAD}file = \"recursive/reflect.rgen.spv\"\n[constants]\nx = 1.5\n"
        ));
        assert_eq!(msg, "constant `x` must be an integer, found float");
        let (msg, line, _) = bad(&format!(
            "{HEAD}file = \"recursive/reflect.rgen.spv\"\n[[hit_group]]\nclosest_hit = {{ file = \"recursive/reflect.rchit.spv\", entyr = \"main\" }}\n"
        ));
        assert!(msg.contains("unknown field `entyr`"), "{msg}");
        assert_eq!(line, 5);
        let (msg, line, _) = bad(&format!(
            "{HEAD}file = \"recursive/reflect.rgen.spv\"\n[[hit_group]]\ntype = \"aabbs\"\n"
        ));
        assert!(msg.starts_with("unknown hit group type `aabbs`"), "{msg}");
        assert_eq!(line, 5);
    }

    fn library(rel: &str) -> (Program, Subobjects) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
        front::load_library(&path, None, Language::Hlsl, &Default::default()).unwrap()
    }

    #[test]
    fn subobjects_describe_the_library_pipeline() {
        let (program, subobjects) = library("fixtures/RT021/good.hlsl");
        let p = Pipeline::from_subobjects(program, &subobjects).unwrap();
        assert!(!p.described(), "the SBT order stays unknown");
        assert_eq!(p.file(), p.subobject_library.clone().unwrap());
        assert_eq!(p.max_recursion_depth, Some(3));
        assert_eq!(p.max_recursion_depth_location.as_ref().unwrap().line, 10);
        assert_eq!(p.max_payload_bytes.as_ref().unwrap().value, 16);
        assert_eq!(p.max_attribute_bytes.as_ref().unwrap().value, 8);
        let entries = |v: &[ShaderRef]| v.iter().map(|s| s.entry.clone()).collect::<Vec<_>>();
        assert_eq!(entries(&p.raygen), ["Gen"]);
        assert_eq!(entries(&p.miss), ["Sky"]);
        assert_eq!(p.hit_groups.len(), 1);
        let g = &p.hit_groups[0];
        assert_eq!(g.kind, HitGroupKind::Triangles);
        assert_eq!(g.closest_hit.as_ref().unwrap().entry, "MirrorHit");
        assert!(g.any_hit.is_none());
        assert_eq!(g.location.as_ref().unwrap().line, 8);
    }

    #[test]
    fn subobjects_naming_shaders_of_another_library_describe_nothing() {
        // `Spheres` names `SphereAny` and `SphereHit`, defined elsewhere.
        let (program, subobjects) = library("tests/hlsl/subobjects.hlsl");
        assert_eq!(subobjects.max_recursion_depth(), Some(3));
        let program = Pipeline::from_subobjects(program, &subobjects).unwrap_err();
        assert_eq!(program.entry_points.len(), 3);
        // Without subobjects: no description either.
        assert!(Pipeline::from_subobjects(*program, &Subobjects::default()).is_err());
    }

    #[test]
    fn a_description_keeps_the_depths_its_libraries_declare() {
        let p =
            load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/RT026/bad.pipeline.toml"))
                .unwrap();
        assert_eq!(p.max_recursion_depth, Some(2));
        let depths: Vec<(u32, u32)> = p
            .subobject_depths
            .iter()
            .map(|d| (d.value, d.location.line))
            .collect();
        assert_eq!(depths, [(3, 10)]);
        assert!(p.subobject_library.is_none());
    }

    #[test]
    fn without_description_everything_is_in() {
        let path = dir().join("recursive/reflect.rchit.spv");
        let prog = crate::front::load(&path, Language::Spirv).unwrap();
        let p = Pipeline::from_programs(vec![prog]);
        assert!(!p.described());
        assert_eq!(p.hit_groups.len(), 1);
        assert_eq!(p.max_recursion_depth, None);
    }
}
