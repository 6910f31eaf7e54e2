//! `rtlint tradeoff`: sweeps the knobs of the reference reflection shaders
//! (bounce depth, rays per pixel, reflection `t_max`, the roughness cut-off,
//! robust origins against a fixed epsilon, recursive against iterative) and
//! measures for each setting the GPU time (timestamp queries, median of
//! repeated dispatches after a warm-up) and the error against a converged
//! image: the CPU reference of the glossy shader's math at the deepest
//! bounce count and many rays per pixel, in `f32` before any 8-bit packing.
//!
//! What is swept is one table, [`KNOBS`]: a knob is a row naming the shader
//! input it sets, the shaders it applies to, and its values. Every GPU run is
//! a child process, as in `rtlint verify` (lavapipe may crash).

pub mod pareto;
pub mod plot;

use crate::reference::{self, Method, Params, Scene, Vec3};
use crate::verify::gpu::HALF_RES_BINDING;
use crate::verify::{self, CaseKind, Loaded, Manifest, Source};
use crate::vk::{spawn_command, ChildOutcome};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// How long one child may run.
pub const CHILD_TIMEOUT: Duration = Duration::from_secs(120);

/// A knob: one shader input, the shaders it is swept on, and its values.
/// Values are text, as they appear in a setting's name (`spp=16`).
pub struct Knob {
    pub name: &'static str,
    /// What the value sets, for the table's legend.
    pub doc: &'static str,
    pub shaders: &'static [&'static str],
    pub values: &'static [&'static str],
    /// The `--quick` sweep: these shaders and values (none: not swept).
    pub quick_shaders: &'static [&'static str],
    pub quick_values: &'static [&'static str],
    /// Sets the value on the uniform parameters.
    pub apply: fn(&mut Params, &Scene, &str) -> Result<(), String>,
}

fn number<T: std::str::FromStr>(knob: &str, v: &str) -> Result<T, String> {
    v.parse()
        .map_err(|_| format!("bad value `{v}` for knob `{knob}`"))
}

/// A count of adaptive paths per pixel: 1 to [`MAX_PATHS`].
fn paths(knob: &str, v: &str) -> Result<u32, String> {
    let n: u32 = number(knob, v)?;
    if !(1..=MAX_PATHS).contains(&n) {
        return Err(format!("{knob} must be 1–{MAX_PATHS}"));
    }
    Ok(n)
}

/// The most adaptive paths per pixel a setting may ask for: each is a pass
/// over the image, and the converged image's sample numbers start above
/// them ([`reference::adaptive::CONVERGED_FIRST_SAMPLE`]).
pub const MAX_PATHS: u32 = 1024;

/// The knobs, in sweep order. Adding one is adding a row (and, when it is a
/// new shader input, the field in [`Params`] and the shaders that read it).
pub const KNOBS: &[Knob] = &[
    Knob {
        name: "bounces",
        doc: "bounce depth (`Params.max_bounces`); recursive pipelines declare depth bounces + 2",
        shaders: &[
            "iterative",
            "recursive",
            "rayquery",
            "glossy",
            "iterative-hlsl",
            "recursive-hlsl",
        ],
        values: &["1", "2", "3", "4", "5", "6", "7", "8"],
        quick_shaders: &["iterative", "recursive"],
        quick_values: &["1"],
        apply: |p, _, v| {
            let n: u32 = number("bounces", v)?;
            if !(1..=30).contains(&n) {
                return Err("bounces must be 1–30".into());
            }
            p.max_bounces = n;
            Ok(())
        },
    },
    Knob {
        name: "spp",
        doc: "rays per pixel of the glossy shader (`Params.flags` bits 8–15)",
        shaders: &["glossy", "glossy-hlsl"],
        values: &["1", "2", "4", "8", "16"],
        quick_shaders: &["glossy"],
        quick_values: &["1", "16"],
        apply: |p, _, v| {
            let n: u32 = number("spp", v)?;
            if !(1..=16).contains(&n) {
                return Err("spp must be 1–16".into());
            }
            p.samples = n;
            Ok(())
        },
    },
    Knob {
        name: "tmax",
        doc: "reflection rays' `t_max` as a fraction of the scene's diagonal, before the glossy \
              shader divides it by 1 + 64 roughness (`Params.knobs.x`)",
        shaders: &["glossy"],
        values: &["0.05", "0.1", "0.25", "0.5", "1", "2"],
        quick_shaders: &["glossy"],
        quick_values: &["0.1"],
        apply: |p, scene, v| {
            let f: f32 = number("tmax", v)?;
            if f.is_nan() || f <= 0.0 {
                return Err("tmax must be above 0".into());
            }
            p.reflect_t_max = f * diagonal(scene);
            Ok(())
        },
    },
    Knob {
        name: "rough_cutoff",
        doc: "roughness above which the environment replaces the reflection ray \
              (`Params.knobs.y`)",
        shaders: &["glossy"],
        values: &["0.25", "0.5"],
        quick_shaders: &["glossy"],
        quick_values: &["0.25"],
        apply: |p, _, v| {
            p.rough_cutoff = number("rough_cutoff", v)?;
            Ok(())
        },
    },
    Knob {
        name: "half_res",
        doc: "half-resolution reflections: a pixel whose first hit is rougher than this takes \
              the reflection its 2×2 block's top-left pixel traced in a quarter-size pass \
              before (`Params.knobs.z`; WGSL only)",
        shaders: &["glossy"],
        values: &["0.1", "0.5"],
        quick_shaders: &["glossy"],
        quick_values: &["0.1"],
        apply: |p, _, v| {
            let r: f32 = number("half_res", v)?;
            if !(0.0..=1.0).contains(&r) {
                return Err("half_res must be 0–1".into());
            }
            p.half_res = r;
            Ok(())
        },
    },
    Knob {
        name: "ssr",
        doc: "the hybrid shader marches the screen first (`on`) or traces every reflection \
              (`off`: ray only; `Params.flags` bit 2)",
        shaders: &["hybrid", "hybrid-hlsl"],
        values: &["on", "off"],
        quick_shaders: &["hybrid"],
        quick_values: &["off"],
        apply: |p, _, v| {
            p.ray_only = match v {
                "on" => false,
                "off" => true,
                _ => return Err(format!("bad value `{v}` for knob `ssr`")),
            };
            Ok(())
        },
    },
    Knob {
        name: "tolerance",
        doc: "the adaptive shader's variance tolerance (`Params.camera.w`); it traces 4 to 16 \
              paths per pixel over 16 passes by default",
        shaders: &["adaptive", "adaptive-hlsl"],
        values: &["1e-2", "1e-3", "1e-4", "1e-5"],
        quick_shaders: &["adaptive"],
        quick_values: &["1e-2"],
        apply: |p, _, v| {
            let t: f32 = number("tolerance", v)?;
            if t.is_nan() || t < 0.0 {
                return Err("tolerance must be 0 or above".into());
            }
            p.tolerance = t;
            Ok(())
        },
    },
    Knob {
        name: "min_paths",
        doc: "the adaptive shader's fewest paths per pixel, at the default most (16) and \
              tolerance (`Params.knobs.w` bits 0–15)",
        shaders: &["adaptive", "adaptive-hlsl"],
        values: &["1", "2", "4", "8"],
        quick_shaders: &["adaptive"],
        quick_values: &["1"],
        apply: |p, _, v| {
            p.adaptive_min = paths("min_paths", v)?;
            Ok(())
        },
    },
    Knob {
        name: "max_paths",
        doc: "the adaptive shader's most paths per pixel, which is also its pass count, at the \
              default fewest (4) and tolerance (`Params.knobs.w` bits 16–31)",
        shaders: &["adaptive", "adaptive-hlsl"],
        values: &["8", "16", "32", "64"],
        quick_shaders: &["adaptive"],
        quick_values: &["8"],
        apply: |p, _, v| {
            p.adaptive_max = paths("max_paths", v)?;
            Ok(())
        },
    },
    Knob {
        name: "origin",
        doc: "ray origins: `robust` (Wächter & Binder) or `epsilon` (p + 1e-3 n; `Params.flags` bit 1)",
        shaders: &["iterative", "glossy", "hybrid"],
        values: &["robust", "epsilon"],
        quick_shaders: &["glossy"],
        quick_values: &["epsilon"],
        apply: |p, _, v| {
            p.robust = match v {
                "robust" => true,
                "epsilon" => false,
                _ => return Err(format!("bad value `{v}` for knob `origin`")),
            };
            Ok(())
        },
    },
];

/// The length of the diagonal of the scene's bounding box.
pub fn diagonal(scene: &Scene) -> f32 {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for t in &scene.triangles {
        for c in t.corners {
            lo = lo.min(c);
            hi = hi.max(c);
        }
    }
    if lo.x > hi.x {
        return 1.0;
    }
    (hi - lo).length()
}

/// How big a sweep is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sweep {
    pub width: u32,
    pub height: u32,
    /// Untimed dispatches before the timed ones (lavapipe compiles the
    /// pipeline at its first).
    pub warmup: u32,
    /// Timed dispatches per child; the median over all rounds is reported.
    pub repeats: u32,
    /// Children per setting, one per pass over the whole sweep.
    pub rounds: u32,
    /// The converged reference: glossy paths per pixel and bounces.
    pub reference_samples: u32,
    pub reference_bounces: u32,
}

pub const FULL: Sweep = Sweep {
    width: 128,
    height: 128,
    warmup: 2,
    repeats: 11,
    rounds: 3,
    reference_samples: 512,
    reference_bounces: 8,
};

pub const QUICK: Sweep = Sweep {
    width: 32,
    height: 32,
    warmup: 1,
    repeats: 5,
    rounds: 1,
    reference_samples: 128,
    reference_bounces: 8,
};

/// One point of the sweep: a shader with some knobs set away from its
/// defaults. Its name is `shader knob=value …` (just `shader` for the
/// defaults).
#[derive(Clone, Debug, PartialEq)]
pub struct Setting {
    pub shader: String,
    pub knobs: Vec<(String, String)>,
}

impl Setting {
    pub fn name(&self) -> String {
        let mut s = self.shader.clone();
        for (k, v) in &self.knobs {
            s.push_str(&format!(" {k}={v}"));
        }
        s
    }

    pub fn parse(name: &str) -> Result<Setting, String> {
        let mut words = name.split_whitespace();
        let shader = words
            .next()
            .ok_or_else(|| "an empty setting".to_string())?
            .to_string();
        let knobs = words
            .map(|w| {
                let (k, v) = w
                    .split_once('=')
                    .ok_or_else(|| format!("`{w}` in setting `{name}` is not knob=value"))?;
                knob(k)?;
                Ok((k.to_string(), v.to_string()))
            })
            .collect::<Result<_, String>>()?;
        Ok(Setting { shader, knobs })
    }

    /// Sets the knobs on `params`.
    pub fn apply(&self, params: &mut Params, scene: &Scene) -> Result<(), String> {
        for (k, v) in &self.knobs {
            (knob(k)?.apply)(params, scene, v)?;
        }
        if params.adaptive_min > params.adaptive_max {
            return Err(format!(
                "setting `{}`: min_paths {} is above max_paths {}",
                self.name(),
                params.adaptive_min,
                params.adaptive_max
            ));
        }
        Ok(())
    }

    /// `knob`'s value, when set.
    pub fn get(&self, knob: &str) -> Option<&str> {
        self.knobs
            .iter()
            .find(|(k, _)| k == knob)
            .map(|(_, v)| v.as_str())
    }
}

fn knob(name: &str) -> Result<&'static Knob, String> {
    KNOBS.iter().find(|k| k.name == name).ok_or_else(|| {
        let names: Vec<&str> = KNOBS.iter().map(|k| k.name).collect();
        format!("unknown knob `{name}` (known: {})", names.join(", "))
    })
}

/// What a shader of the manifest runs and which CPU reference follows it.
fn shader_source(manifest: &Manifest, shader: &str) -> Option<(Source, Method)> {
    manifest.cases.iter().find_map(|c| match &c.kind {
        CaseKind::Render {
            source,
            method,
            extreme: None,
            ..
        } if c.shader == shader => Some((source.clone(), *method)),
        _ => None,
    })
}

/// The settings of a sweep over `scene_name` in the `shaders` folder: each
/// shader's defaults, then every knob's values on each of its shaders, the
/// others at their defaults. Shaders the manifest lacks are left out; a
/// knob value that equals the defaults is the defaults' row.
pub fn settings(
    manifest: &Manifest,
    shaders: &Path,
    scene_name: &str,
    quick: bool,
) -> Result<Vec<Setting>, String> {
    let mut names: Vec<&str> = Vec::new();
    for k in KNOBS {
        let list = if quick { k.quick_shaders } else { k.shaders };
        for s in list {
            if !names.contains(s) && shader_source(manifest, s).is_some() {
                names.push(s);
            }
        }
    }
    // Each shader's defaults as verify sets them up (the bounce count from
    // its pipeline description).
    let path = scene_path(shaders, scene_name);
    let scene = Scene::load(&path)?;
    let mut defaults = Vec::new();
    for name in &names {
        let (source, _) = shader_source(manifest, name)
            .ok_or_else(|| format!("no shader `{name}` in the manifest"))?;
        defaults.push(verify::setup(manifest, &source, &path, None)?.2);
    }
    let mut out: Vec<(Setting, Vec<u32>)> = Vec::new();
    let mut push = |s: Setting| -> Result<(), String> {
        let k = names.iter().position(|n| *n == s.shader).unwrap_or(0);
        let mut params = defaults[k];
        s.apply(&mut params, &scene)?;
        let words = params.to_words().to_vec();
        if !out.iter().any(|(o, w)| o.shader == s.shader && *w == words) {
            out.push((s, words));
        }
        Ok(())
    };
    for s in &names {
        push(Setting {
            shader: s.to_string(),
            knobs: Vec::new(),
        })?;
    }
    for k in KNOBS {
        let (list, values) = if quick {
            (k.quick_shaders, k.quick_values)
        } else {
            (k.shaders, k.values)
        };
        for s in list.iter().filter(|s| names.contains(s)) {
            for v in values {
                push(Setting {
                    shader: s.to_string(),
                    knobs: vec![(k.name.to_string(), v.to_string())],
                })?;
            }
        }
    }
    Ok(out.into_iter().map(|(s, _)| s).collect())
}

/// A setting ready to run: its shaders loaded, the scene, the parameters,
/// the recursion depth to declare, and which CPU reference follows it.
struct Prepared {
    loaded: Loaded,
    scene: Scene,
    params: Params,
    depth: Option<u32>,
    method: Method,
}

fn prepare(
    shaders: &Path,
    scene_name: &str,
    sweep: &Sweep,
    setting: &Setting,
) -> Result<Prepared, String> {
    let manifest = Manifest::load(shaders)?;
    let (source, method) = shader_source(&manifest, &setting.shader)
        .ok_or_else(|| format!("no shader `{}` in the manifest", setting.shader))?;
    let scene_path = scene_path(shaders, scene_name);
    let (loaded, scene, mut params) = verify::setup(&manifest, &source, &scene_path, None)?;
    params.width = sweep.width;
    params.height = sweep.height;
    setting.apply(&mut params, &scene)?;
    // A recursive pipeline declares what its bounce count needs: its
    // description's depth less the bounces it was described for, plus ours.
    let depth = match &loaded {
        Loaded::Pipeline(p) => match (p.max_recursion_depth, p.constant("params.max_bounces")) {
            (Some(d), Some(c)) if d > 1 => {
                let extra = i64::from(d) - c.value;
                Some(u32::try_from(i64::from(params.max_bounces) + extra).unwrap_or(d))
            }
            _ => None,
        },
        Loaded::Compute { .. } => None,
    };
    Ok(Prepared {
        loaded,
        scene,
        params,
        depth,
        method,
    })
}

fn scene_path(shaders: &Path, scene: &str) -> PathBuf {
    shaders.join("scenes").join(format!("{scene}.toml"))
}

/// The child's side: renders `setting` on the device, times it, writes the
/// packed image to `image`. Prints `device: NAME`, `timestamps: BITS PERIOD`
/// and `gpu-ns: T…` (one per timed dispatch) on stdout.
pub fn child_main(
    shaders: &Path,
    scene: &str,
    quick: bool,
    setting: &str,
    image: &Path,
    device: Option<&str>,
) -> Result<(), String> {
    let sweep = if quick { QUICK } else { FULL };
    let setting = Setting::parse(setting)?;
    let p = prepare(shaders, scene, &sweep, &setting)?;
    let ctx = crate::vk::Context::with_options(&crate::vk::ContextOptions {
        device_name: device.map(str::to_string),
        ..Default::default()
    })
    .map_err(|e| e.to_string())?;
    println!("device: {}", ctx.info().name);
    let ts = ctx.timestamps();
    println!("timestamps: {} {}", ts.valid_bits, ts.period_ns);
    if ts.valid_bits == 0 {
        println!(
            "skip: the queue of {} writes no timestamps",
            ctx.info().name
        );
        return Err(verify::SKIP.into());
    }
    let vk = |e: crate::vk::Error| e.to_string();
    let gpu_scene = verify::gpu::GpuScene::new(&ctx, &p.scene).map_err(vk)?;
    let params = &p.params;
    let pixels = u64::from(params.width) * u64::from(params.height);
    let out = crate::vk::Buffer::new(
        &ctx,
        pixels * 4,
        crate::vk::raw::BufferUsageFlags::STORAGE_BUFFER,
        1,
    )
    .map_err(vk)?;
    let uniform = crate::vk::Buffer::from_data(
        &ctx,
        crate::vk::raw::BufferUsageFlags::UNIFORM_BUFFER,
        &params.to_words(),
    )
    .map_err(vk)?;
    let half = verify::gpu::half_res_buffer(&ctx, params).map_err(vk)?;
    let mut resources = gpu_scene.resources(&out, &uniform);
    for r in &mut resources {
        if r.0 == HALF_RES_BINDING {
            r.1 = crate::vk::Resource::Buffer(&half);
        }
    }
    // Multi-pass shaders (hybrid, adaptive) keep per-pixel state between
    // passes: zeroed before each timed run, as for a fresh frame.
    let passes = verify::gpu::Passes::for_method(p.method, params);
    let usage = crate::vk::raw::BufferUsageFlags::STORAGE_BUFFER
        | crate::vk::raw::BufferUsageFlags::TRANSFER_DST;
    let scratch = if passes.scratch {
        Some((
            crate::vk::Buffer::new(&ctx, pixels * 4, usage, 1).map_err(vk)?,
            crate::vk::Buffer::new(&ctx, pixels * verify::gpu::SCRATCH_BYTES, usage, 1)
                .map_err(vk)?,
        ))
    } else {
        None
    };
    if let Some((counts, state)) = &scratch {
        resources.push((6, crate::vk::Resource::Buffer(counts)));
        resources.push((7, crate::vk::Resource::Buffer(state)));
    }
    let times = match &p.loaded {
        Loaded::Pipeline(pipeline) => {
            let rt =
                verify::gpu::ray_tracing_pipeline_for(&ctx, pipeline, p.depth, &p.scene, passes)?;
            let (w, h) = (params.width, params.height);
            let raygens = if passes.repeat > 1 || passes.scratch {
                pipeline.raygen.len()
            } else {
                1
            };
            let mut run: Vec<(usize, [u32; 2])> = Vec::new();
            // Half-resolution mode: the block pass first.
            if params.half_res <= 1.0 {
                run.push((0, [w.div_ceil(2), h.div_ceil(2)]));
            }
            for _ in 0..passes.repeat {
                run.extend((0..raygens).map(|r| (r, [w, h])));
            }
            let clear: Vec<&crate::vk::Buffer> = scratch.iter().flat_map(|(c, s)| [c, s]).collect();
            rt.time_trace_rays(&resources, &run, &clear, sweep.warmup, sweep.repeats)
                .map_err(vk)?
        }
        Loaded::Compute { words, entry } => {
            if !ctx.info().ray_query {
                println!("skip: {} has no VK_KHR_ray_query", ctx.info().name);
                return Err(verify::SKIP.into());
            }
            let cp = crate::vk::ComputePipeline::new(
                &ctx,
                words,
                entry,
                &verify::gpu::bindings(&p.scene),
            )
            .map_err(vk)?;
            cp.time_dispatch(
                &resources,
                [params.width.div_ceil(8), params.height.div_ceil(8), 1],
                sweep.warmup,
                sweep.repeats,
            )
            .map_err(vk)?
        }
    };
    let line: Vec<String> = times.iter().map(|t| format!("{t:.0}")).collect();
    println!("gpu-ns: {}", line.join(" "));
    let bytes: Vec<u8> = out
        .read_u32()
        .iter()
        .flat_map(|p| p.to_le_bytes())
        .collect();
    std::fs::write(image, bytes).map_err(|e| format!("cannot write {}: {e}", image.display()))
}

/// How to run a sweep.
pub struct Options<'a> {
    pub shaders: PathBuf,
    pub out: PathBuf,
    pub scene: String,
    pub quick: bool,
    /// Builds the command that runs one setting in a child process (the
    /// child calls [`child_main`] and writes the image to the given file).
    pub child: &'a dyn Fn(&str, &Path) -> Command,
}

/// What one setting measured.
#[derive(Clone, Debug)]
pub struct Measured {
    /// Median, fastest and slowest timed dispatch, in milliseconds.
    pub gpu_ms: f64,
    pub gpu_ms_min: f64,
    pub gpu_ms_max: f64,
    pub error: Error,
    /// Rays the setting traces for the whole image (primary, reflection
    /// and shadow), counted on its CPU reference, which follows the same
    /// paths.
    pub rays: u64,
    /// Largest channel difference between the GPU image and the CPU
    /// reference of the same setting, in 8-bit steps.
    pub cpu_diff: u8,
    pub image: Vec<u32>,
}

/// Error of an image against the converged reference, per RGB channel in
/// [0, 1]. A NaN or infinite pixel counts as fully wrong.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Error {
    pub rmse: f64,
    pub psnr: f64,
    pub max: f64,
}

/// The error of a packed RGBA8 image against `reference`.
pub fn error(image: &[u32], reference: &[Vec3]) -> Error {
    let (mut sq, mut max) = (0.0f64, 0.0f64);
    for (&p, r) in image.iter().zip(reference) {
        let c = reference::unpack_rgba8(p);
        let r = r.clamp(Vec3::ZERO, Vec3::ONE);
        for (k, want) in [r.x, r.y, r.z].into_iter().enumerate() {
            let got = if c[3] == 0 {
                f64::NAN
            } else {
                f64::from(c[k]) / 255.0
            };
            let d = (got - f64::from(want)).abs();
            let d = if d.is_finite() { d } else { 1.0 };
            sq += d * d;
            max = max.max(d);
        }
    }
    let n = (image.len().min(reference.len()) * 3).max(1) as f64;
    let rmse = (sq / n).sqrt();
    Error {
        rmse,
        psnr: if rmse == 0.0 {
            f64::INFINITY
        } else {
            -20.0 * rmse.log10()
        },
        max,
    }
}

#[derive(Clone, Debug)]
pub enum Outcome {
    Measured(Box<Measured>),
    Skipped(String),
    Failed(String),
}

#[derive(Clone, Debug)]
pub struct Row {
    pub setting: Setting,
    pub outcome: Outcome,
    /// On the Pareto front of GPU time against RMSE.
    pub front: bool,
}

impl Row {
    pub fn measured(&self) -> Option<&Measured> {
        match &self.outcome {
            Outcome::Measured(m) => Some(m),
            _ => None,
        }
    }
}

/// The whole sweep.
#[derive(Clone, Debug)]
pub struct Report {
    pub device: Option<String>,
    /// `timestampValidBits` and `timestampPeriod` (ns) the children saw.
    pub timestamps: Option<String>,
    pub scene: String,
    pub sweep: Sweep,
    pub rows: Vec<Row>,
    /// The converged reference, clamped to [0, 1].
    pub reference: Vec<Vec3>,
}

/// The converged reference: the glossy shader's paths averaged over
/// `sweep.reference_samples` per pixel at `sweep.reference_bounces`, robust
/// origins, full `t_max`, no roughness cut-off; rendered by the CPU
/// reference in `f32`.
pub fn converged(scene: &Scene, sweep: &Sweep) -> Vec<Vec3> {
    let params = Params::for_scene(scene, sweep.width, sweep.height, sweep.reference_bounces);
    (0..sweep.width * sweep.height)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % sweep.width, i / sweep.width);
            reference::glossy_mean(scene, &params, x, y, sweep.reference_samples)
                .clamp(Vec3::ZERO, Vec3::ONE)
        })
        .collect()
}

/// The CPU reference of one setting: its image and the rays it traces.
fn cpu_render(p: &Prepared) -> (Vec<u32>, u64) {
    if p.method == Method::Hybrid {
        // Its pixels read one G-buffer of the whole image.
        let (paths, _) = reference::hybrid::render(&p.scene, &p.params);
        let rays = paths.iter().map(|q| q.segments.len() as u64).sum();
        return (
            paths
                .iter()
                .map(|q| reference::pack_rgba8(q.color))
                .collect(),
            rays,
        );
    }
    let w = p.params.width;
    let pixels: Vec<(u32, u64)> = (0..w * p.params.height)
        .into_par_iter()
        .map(|i| {
            let path = reference::trace_pixel(&p.scene, &p.params, p.method, i % w, i / w);
            (
                reference::pack_rgba8(path.color),
                path.segments.len() as u64,
            )
        })
        .collect();
    let rays = pixels.iter().map(|p| p.1).sum();
    (pixels.into_iter().map(|p| p.0).collect(), rays)
}

fn describe(end: &ChildOutcome) -> String {
    let last = end.stderr.lines().rev().find(|l| !l.trim().is_empty());
    match (end.timed_out, end.signal, end.code, last) {
        (true, _, _, _) => format!(
            "the child ran past {} s and was killed",
            CHILD_TIMEOUT.as_secs()
        ),
        (_, Some(s), _, _) => format!("the child was killed by signal {s}"),
        (_, _, Some(c), Some(l)) => format!("the child exited with {c}: {}", l.trim()),
        (_, _, Some(c), None) => format!("the child exited with {c}"),
        _ => "the child ended without a status".into(),
    }
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    match s.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => s[n / 2],
        n => 0.5 * (s[n / 2 - 1] + s[n / 2]),
    }
}

/// A setting's timed dispatches (ms) over every round, and its image.
type Timed = (Vec<f64>, Vec<u32>);

/// Runs the sweep; `progress` is told before each setting starts. An `Err`
/// is a usage or input problem (exit 2); a failed setting is a row.
pub fn run(
    options: &Options<'_>,
    mut progress: impl FnMut(usize, usize, &str),
) -> Result<Report, String> {
    let sweep = if options.quick { QUICK } else { FULL };
    let manifest = Manifest::load(&options.shaders)?;
    let scene = Scene::load(&scene_path(&options.shaders, &options.scene))?;
    let settings = settings(&manifest, &options.shaders, &options.scene, options.quick)?;
    if settings.is_empty() {
        return Err("the manifest names none of the shaders the knobs apply to".into());
    }
    // Inputs are checked before any GPU work: a bad value is a usage error.
    let prepared = settings
        .iter()
        .map(|s| prepare(&options.shaders, &options.scene, &sweep, s))
        .collect::<Result<Vec<_>, _>>()?;
    std::fs::create_dir_all(&options.out)
        .map_err(|e| format!("cannot create {}: {e}", options.out.display()))?;
    // The bar counts GPU runs (settings × rounds); the CPU reference is
    // the message at the end, not one more step.
    let total = settings.len() * sweep.rounds as usize;
    // The GPU runs come first and alone: on lavapipe the "GPU" is these
    // CPU cores, and CPU work beside a child would slow its timings.
    // Rounds over the whole sweep, so that a stretch of load from other
    // work slows one round of a setting rather than all its dispatches.
    let mut runs: Vec<Result<Timed, Outcome>> = vec![Ok((Vec::new(), Vec::new())); settings.len()];
    let (mut device, mut timestamps) = (None, None);
    for round in 0..sweep.rounds {
        for (i, s) in settings.iter().enumerate() {
            let Ok((times, pixels)) = &mut runs[i] else {
                continue;
            };
            let name = s.name();
            progress(round as usize * settings.len() + i, total, &name);
            let image = options.out.join(format!("{}.rgba", file_name(&name)));
            let _ = std::fs::remove_file(&image);
            let end = spawn_command((options.child)(&name, &image))
                .map_err(|e| format!("cannot start the child process: {e}"))?
                .wait(CHILD_TIMEOUT)
                .map_err(|e| e.to_string())?;
            let field = |key: &str| {
                end.stdout
                    .lines()
                    .find_map(|l| l.strip_prefix(key))
                    .map(str::to_string)
            };
            device = device.or_else(|| field("device: "));
            timestamps = timestamps.or_else(|| field("timestamps: "));
            if end.code == Some(verify::SKIP_CODE) {
                runs[i] = Err(Outcome::Skipped(
                    field("skip: ").unwrap_or_else(|| "the device cannot run it".into()),
                ));
                continue;
            }
            if end.code != Some(0) {
                runs[i] = Err(Outcome::Failed(describe(&end)));
                continue;
            }
            let new: Vec<f64> = field("gpu-ns: ")
                .unwrap_or_default()
                .split_whitespace()
                .filter_map(|t| t.parse::<f64>().ok())
                .map(|ns| ns / 1e6)
                .collect();
            let bytes = std::fs::read(&image).unwrap_or_default();
            let _ = std::fs::remove_file(&image);
            let image: Vec<u32> = bytes
                .chunks_exact(4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect();
            if new.is_empty() || image.len() != (sweep.width * sweep.height) as usize {
                runs[i] = Err(Outcome::Failed(format!(
                    "the child reported {} times and {} pixels",
                    new.len(),
                    image.len()
                )));
                continue;
            }
            if !pixels.is_empty() && *pixels != image {
                runs[i] = Err(Outcome::Failed(format!(
                    "round {} rendered a different image",
                    round + 1
                )));
                continue;
            }
            times.extend(new);
            *pixels = image;
        }
    }
    progress(total, total, "converged reference (CPU)");
    let reference = converged(&scene, &sweep);
    let mut rows = Vec::new();
    for ((setting, p), run) in settings.into_iter().zip(&prepared).zip(runs) {
        let outcome = match run {
            Err(o) => o,
            Ok((times, image)) => {
                let (cpu, rays) = cpu_render(p);
                let cpu_diff = image
                    .iter()
                    .zip(&cpu)
                    .map(|(&g, &c)| {
                        let (g, c) = (reference::unpack_rgba8(g), reference::unpack_rgba8(c));
                        (0..3).map(|k| g[k].abs_diff(c[k])).max().unwrap_or(0)
                    })
                    .max()
                    .unwrap_or(0);
                Outcome::Measured(Box::new(Measured {
                    gpu_ms: median(&times),
                    gpu_ms_min: times.iter().copied().fold(f64::INFINITY, f64::min),
                    gpu_ms_max: times.iter().copied().fold(0.0, f64::max),
                    error: error(&image, &reference),
                    rays,
                    cpu_diff,
                    image,
                }))
            }
        };
        rows.push(Row {
            setting,
            outcome,
            front: false,
        });
    }
    progress(total, total, "");
    let points: Vec<Option<(f64, f64)>> = rows
        .iter()
        .map(|r| r.measured().map(|m| (m.gpu_ms, m.error.rmse)))
        .collect();
    for (r, on) in rows.iter_mut().zip(pareto::front(&points)) {
        r.front = on;
    }
    Ok(Report {
        device,
        timestamps,
        scene: options.scene.clone(),
        sweep,
        rows,
        reference,
    })
}

/// A setting's name as a file name.
pub fn file_name(setting: &str) -> String {
    setting
        .chars()
        .map(|c| match c {
            ' ' => '_',
            '=' => '-',
            c if c.is_ascii_alphanumeric() || c == '.' || c == '-' || c == '_' => c,
            _ => '_',
        })
        .collect()
}

/// The table's columns, in order.
pub const COLUMNS: [&str; 13] = [
    "setting",
    "shader",
    "knob",
    "value",
    "gpu_ms",
    "gpu_ms_min",
    "gpu_ms_max",
    "rmse",
    "psnr_db",
    "max_error",
    "rays",
    "cpu_diff",
    "front",
];

impl Row {
    /// The row's cells under [`COLUMNS`], then the result.
    pub fn cells(&self) -> Vec<String> {
        let (knob, value) = self
            .setting
            .knobs
            .first()
            .map(|(k, v)| (k.clone(), v.clone()))
            .unwrap_or_else(|| ("-".into(), "default".into()));
        let mut cells = vec![
            self.setting.name(),
            self.setting.shader.clone(),
            knob,
            value,
        ];
        match &self.outcome {
            Outcome::Measured(m) => {
                cells.extend([
                    format!("{:.4}", m.gpu_ms),
                    format!("{:.4}", m.gpu_ms_min),
                    format!("{:.4}", m.gpu_ms_max),
                    format!("{:.5}", m.error.rmse),
                    if m.error.psnr.is_infinite() {
                        "inf".into()
                    } else {
                        format!("{:.2}", m.error.psnr)
                    },
                    format!("{:.4}", m.error.max),
                    m.rays.to_string(),
                    m.cpu_diff.to_string(),
                    if self.front { "yes" } else { "no" }.into(),
                    "measured".into(),
                ]);
            }
            Outcome::Skipped(why) | Outcome::Failed(why) => {
                cells.extend(std::iter::repeat_n("-".to_string(), 8));
                cells.push("no".into());
                let kind = if matches!(self.outcome, Outcome::Skipped(_)) {
                    "skipped"
                } else {
                    "failed"
                };
                cells.push(format!("{kind}: {why}"));
            }
        }
        cells
    }
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

impl Report {
    pub fn csv(&self) -> String {
        let mut out = COLUMNS.join(",") + ",result\n";
        for r in &self.rows {
            let cells: Vec<String> = r.cells().iter().map(|c| csv_field(c)).collect();
            out.push_str(&cells.join(","));
            out.push('\n');
        }
        out
    }

    /// The front's rows, fastest first.
    pub fn front(&self) -> Vec<&Row> {
        let mut f: Vec<&Row> = self.rows.iter().filter(|r| r.front).collect();
        f.sort_by(|a, b| {
            let t = |r: &Row| r.measured().map_or(f64::INFINITY, |m| m.gpu_ms);
            t(a).total_cmp(&t(b))
        });
        f
    }

    fn header(&self) -> String {
        format!(
            "device: {}; timestamps (valid bits, ns per tick): {}; scene `{}` at {}×{}; \
             GPU time: median of {} rounds × {} timed dispatches, each child after {} \
             warm-up; error against the CPU reference of the glossy shader's math at {} \
             bounces and {} rays per pixel (f32, before packing)",
            self.device.as_deref().unwrap_or("none answered"),
            self.timestamps.as_deref().unwrap_or("-"),
            self.scene,
            self.sweep.width,
            self.sweep.height,
            self.sweep.rounds,
            self.sweep.repeats,
            self.sweep.warmup,
            self.sweep.reference_bounces,
            self.sweep.reference_samples,
        )
    }

    pub fn markdown(&self) -> String {
        let mut out = format!("{}\n\n", self.header());
        out.push_str("Pareto front (GPU time against RMSE), fastest first:\n\n");
        out.push_str(
            "| setting | GPU ms (median) | GPU ms (fastest) | RMSE | PSNR dB | max error | rays |\n",
        );
        out.push_str("| --- | --- | --- | --- | --- | --- | --- |\n");
        for r in self.front() {
            let c = r.cells();
            out.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {} |\n",
                c[0], c[4], c[5], c[7], c[8], c[9], c[10]
            ));
        }
        out.push_str("\nEvery setting:\n\n");
        out.push_str(&format!("| {} | result |\n", COLUMNS.join(" | ")));
        out.push_str(&"| --- ".repeat(COLUMNS.len() + 1));
        out.push_str("|\n");
        for r in &self.rows {
            out.push_str(&format!("| {} |\n", r.cells().join(" | ")));
        }
        out.push_str("\nKnobs:\n\n");
        for k in KNOBS {
            out.push_str(&format!(
                "- `{}`: {} (on {})\n",
                k.name,
                k.doc,
                k.shaders.join(", ")
            ));
        }
        out
    }

    /// The table as aligned text: the main columns, then why rows failed.
    pub fn text(&self) -> String {
        let pick = [0usize, 4, 7, 8, 9, 10, 11, 12];
        let mut rows: Vec<Vec<String>> = vec![pick.iter().map(|&i| COLUMNS[i].into()).collect()];
        for r in &self.rows {
            let c = r.cells();
            rows.push(pick.iter().map(|&i| c[i].clone()).collect());
        }
        let mut out = format!("{}\n{}", self.header(), verify::aligned(&rows));
        for r in &self.rows {
            match &r.outcome {
                Outcome::Failed(why) => {
                    out.push_str(&format!("FAIL {}: {why}\n", r.setting.name()))
                }
                Outcome::Skipped(why) => {
                    out.push_str(&format!("skipped {}: {why}\n", r.setting.name()))
                }
                Outcome::Measured(_) => {}
            }
        }
        out
    }

    /// Writes `tradeoff.csv`, `tradeoff.md`, `tradeoff.svg`, the converged
    /// reference and each front setting's image as PNG (`front-NAME.png`).
    pub fn write(&self, out: &Path) -> Result<(), String> {
        let write = |name: &str, text: String| {
            let path = out.join(name);
            std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
        };
        write("tradeoff.csv", self.csv())?;
        write("tradeoff.md", self.markdown())?;
        write("tradeoff.svg", plot::svg(self))?;
        let (w, h) = (self.sweep.width, self.sweep.height);
        let reference: Vec<u32> = self
            .reference
            .iter()
            .map(|&c| reference::pack_rgba8(c))
            .collect();
        verify::compare::write_png(&out.join("reference.png"), &reference, w, h)?;
        // Thumbnails of an earlier sweep's front would read as this one's.
        if let Ok(entries) = std::fs::read_dir(out) {
            for e in entries.flatten() {
                let name = e.file_name().to_string_lossy().into_owned();
                if name.starts_with("front-") && name.ends_with(".png") {
                    let _ = std::fs::remove_file(e.path());
                }
            }
        }
        for r in self.front() {
            if let Some(m) = r.measured() {
                let name = format!("front-{}.png", file_name(&r.setting.name()));
                verify::compare::write_png(&out.join(name), &m.image, w, h)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shaders() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders")
    }

    #[test]
    fn settings_names_round_trip_and_knobs_reach_the_parameters() {
        let manifest = Manifest::load(&shaders()).unwrap();
        let all = settings(&manifest, &shaders(), "showcase", false).unwrap();
        for s in &all {
            assert_eq!(&Setting::parse(&s.name()).unwrap(), s);
        }
        // The defaults' own values are not repeated (bounces=3 is the default).
        assert!(all.iter().any(|s| s.name() == "glossy"));
        assert!(!all.iter().any(|s| s.name() == "glossy bounces=3"));
        assert!(all.iter().any(|s| s.name() == "recursive bounces=8"));
        let p = prepare(
            &shaders(),
            "showcase",
            &QUICK,
            &Setting::parse("recursive bounces=8").unwrap(),
        )
        .unwrap();
        assert_eq!((p.params.max_bounces, p.depth), (8, Some(10)));
        let p = prepare(
            &shaders(),
            "showcase",
            &QUICK,
            &Setting::parse("glossy spp=16 tmax=0.5 rough_cutoff=0.2 origin=epsilon").unwrap(),
        )
        .unwrap();
        assert_eq!(p.params.samples, 16);
        assert_eq!(p.params.reflect_t_max, 0.5 * diagonal(&p.scene));
        assert_eq!((p.params.rough_cutoff, p.params.robust), (0.2, false));
        // The adaptive shader's paths: the uniform's last word, and the
        // passes the GPU runs.
        let p = prepare(
            &shaders(),
            "showcase",
            &QUICK,
            &Setting::parse("adaptive min_paths=2 max_paths=32").unwrap(),
        )
        .unwrap();
        assert_eq!(p.params.to_words()[19], 2 | 32 << 16);
        assert_eq!(p.method.passes(&p.params), 32);
        assert!(all.iter().any(|s| s.name() == "adaptive-hlsl max_paths=64"));
        assert!(!all.iter().any(|s| s.name() == "adaptive min_paths=4"));
        for bad in [
            "adaptive min_paths=0",
            "adaptive min_paths=32",
            "adaptive max_paths=5000",
        ] {
            let setting = Setting::parse(bad).unwrap();
            assert!(
                prepare(&shaders(), "showcase", &QUICK, &setting).is_err(),
                "{bad}"
            );
        }
        assert!(Setting::parse("glossy warp=9").is_err());
        assert!(prepare(
            &shaders(),
            "showcase",
            &QUICK,
            &Setting::parse("glossy spp=99").unwrap()
        )
        .is_err());
    }

    #[test]
    fn error_counts_non_finite_pixels_as_wrong() {
        let reference = vec![Vec3::splat(0.5); 2];
        let grey = reference::pack_rgba8(Vec3::splat(0.5));
        let e = error(&[grey, grey], &reference);
        assert!(e.rmse < 0.003 && e.psnr > 50.0, "{e:?}");
        let e = error(&[grey, 0], &reference);
        assert_eq!(e.max, 1.0);
    }

    #[test]
    fn the_cpu_reference_follows_the_new_knobs() {
        let scene = Scene::load(&scene_path(&shaders(), "showcase")).unwrap();
        let base = Params::for_scene(&scene, 24, 24, 3);
        let rays = |p: &Params| -> usize {
            (0..24 * 24)
                .map(|i| {
                    reference::trace_glossy(&scene, p, i % 24, i / 24)
                        .segments
                        .len()
                })
                .sum()
        };
        // Cutting every rough reflection, or shortening reflection rays,
        // changes the image; the cut-off traces fewer rays.
        let cut = Params {
            rough_cutoff: 0.0,
            ..base
        };
        assert!(rays(&cut) < rays(&base));
        let image = |p: &Params| reference::render(&scene, p, Method::Glossy).0;
        assert_ne!(image(&cut), image(&base));
        let short = Params {
            reflect_t_max: 0.1,
            ..base
        };
        assert_ne!(image(&short), image(&base));
        // Half resolution: rough first hits share their block's reflection
        // (fewer rays); pixels off rough surfaces keep their own.
        let half = Params {
            half_res: 0.1,
            ..base
        };
        assert!(rays(&half) < rays(&base));
        let (a, b) = (image(&half), image(&base));
        let same = a.iter().zip(&b).filter(|(x, y)| x == y).count();
        assert!(
            same > a.len() / 2 && same < a.len(),
            "{same} of {}",
            a.len()
        );
    }
}
