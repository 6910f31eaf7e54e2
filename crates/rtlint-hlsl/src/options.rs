//! What a DXC command line says, as one options type ([`HlslOptions`]), and
//! the reader of DXC's spellings ([`parse_args`]). The meanings follow DXC's
//! documentation of its SPIR-V back-end (`docs/SPIR-V.rst`, "Supported
//! Command-line Options" and "HLSL register and Vulkan binding").

use crate::vocab::Stage;
use std::path::PathBuf;

/// What `rtlint compile`, `check` and the other commands pass to the
/// compiler: the DXC options that change the module.
#[derive(Clone, Debug, Default)]
pub struct HlslOptions {
    /// `-I` directories, searched in order after the including file's folder.
    pub include_dirs: Vec<PathBuf>,
    /// `-D NAME[=VALUE]`; a define without a value is `1`.
    pub defines: Vec<(String, String)>,
    /// `-E`: compile only this entry point.
    pub entry: Option<String>,
    /// The stage of `entry` when it has no `[shader(...)]` (from `-T`).
    pub stage: Option<Stage>,
    /// `-T` as given: the predefined `__SHADER_TARGET_*` macros follow it.
    pub profile: Option<Profile>,
    /// DXC's `-enable-16bit-types`: `half` and the `min16*` types are then
    /// 16-bit, which this compiler refuses rather than widen.
    pub enable_16bit_types: bool,
    /// `-HV`: 2016, 2018, 2021 or 2029 (`202x`); `None` is DXC's default, 2021.
    pub hlsl_version: Option<u32>,
    /// `-Zpr`: matrices without a packing keyword are row-major (`-Zpc`,
    /// DXC's default, is column-major).
    pub row_major: bool,
    /// `-fspv-target-env=`: the predefined `__SPIRV_*_VERSION__` macros
    /// follow it (the module itself is SPIR-V 1.4 whatever it says).
    pub target_env: TargetEnv,
    /// Register to descriptor mapping (`-fvk-*-shift`, `-fvk-bind-register`,
    /// `-fvk-bind-globals`, `-fvk-auto-shift-bindings`, `-auto-binding-space`).
    pub bindings: Bindings,
    /// The command line builds for Vulkan: `-spirv` or any `-fspv-*` or
    /// `-fvk-*` option. (This compiler always writes SPIR-V; a caller
    /// judging the source, such as a lint of register collisions, uses it.)
    pub spirv: bool,
}

/// A target profile: `ps_6_5`, `lib_6_3`, `lib_6_x`, `cs_6_0`, ...
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Profile {
    pub kind: ProfileKind,
    pub major: u32,
    /// `lib_6_x` (offline linking) has minor 15, as in DXC.
    pub minor: u32,
}

/// The stage part of a profile, numbered as DXC numbers shader kinds (the
/// values of its `__SHADER_STAGE_*` macros).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProfileKind {
    Pixel = 0,
    Vertex = 1,
    Geometry = 2,
    Hull = 3,
    Domain = 4,
    Compute = 5,
    Library = 6,
    Mesh = 13,
    Amplification = 14,
}

/// DXC's `-fspv-target-env`: Vulkan 1.0 unless given.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TargetEnv {
    #[default]
    Vulkan1_0,
    Vulkan1_1,
    Vulkan1_1Spirv1_4,
    Vulkan1_2,
    Vulkan1_3,
    Universal1_5,
}

impl TargetEnv {
    fn parse(s: &str) -> Option<TargetEnv> {
        Some(match s {
            "vulkan1.0" => TargetEnv::Vulkan1_0,
            "vulkan1.1" => TargetEnv::Vulkan1_1,
            "vulkan1.1spirv1.4" => TargetEnv::Vulkan1_1Spirv1_4,
            "vulkan1.2" => TargetEnv::Vulkan1_2,
            "vulkan1.3" => TargetEnv::Vulkan1_3,
            "universal1.5" => TargetEnv::Universal1_5,
            _ => return None,
        })
    }

    /// The SPIR-V version DXC associates with the environment.
    pub fn spirv_version(self) -> (u32, u32) {
        match self {
            TargetEnv::Vulkan1_0 => (1, 0),
            TargetEnv::Vulkan1_1 => (1, 3),
            TargetEnv::Vulkan1_1Spirv1_4 => (1, 4),
            TargetEnv::Vulkan1_2 | TargetEnv::Universal1_5 => (1, 5),
            TargetEnv::Vulkan1_3 => (1, 6),
        }
    }
}

/// How `register(...)` becomes a descriptor set and binding. DXC's three
/// passes: `[[vk::binding]]` first, then `register(xN, spaceM)` (binding
/// `N` plus the shift of register class `x` in space `M`, set `M`), then
/// every other resource takes the next free binding of its set (from the
/// shift of its class with `-fvk-auto-shift-bindings`) in declaration order.
/// A collision that remains is not an error, as in DXC.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Bindings {
    /// `-fvk-b-shift`, `-fvk-t-shift`, `-fvk-u-shift`, `-fvk-s-shift`.
    pub b_shift: Shift,
    pub t_shift: Shift,
    pub u_shift: Shift,
    pub s_shift: Shift,
    /// `-fvk-bind-register xN SPACE BINDING SET` (`-vkbr`): every resource
    /// must then have a register listed here.
    pub bind_register: Vec<RegisterBinding>,
    /// `-fvk-bind-globals BINDING SET`: where `$Globals` goes.
    pub bind_globals: Option<(u32, u32)>,
    /// `-fvk-auto-shift-bindings`: a resource without a register is shifted
    /// by the shift of the class its type implies.
    pub auto_shift: bool,
    /// `-auto-binding-space N`: the set of resources without a space.
    pub default_space: u32,
}

/// One `-fvk-bind-register`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RegisterBinding {
    pub class: char,
    pub index: u32,
    pub space: u32,
    pub binding: u32,
    pub set: u32,
}

/// The shifts of one register class: one for every space (`N all`), or one
/// per space (`N SPACE`, the last given for a space wins).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Shift {
    pub all: u32,
    pub per_space: Vec<(u32, u32)>,
}

impl Shift {
    /// The shift for `space`.
    pub fn of(&self, space: u32) -> u32 {
        self.per_space
            .iter()
            .rev()
            .find(|(s, _)| *s == space)
            .map(|&(_, n)| n)
            .unwrap_or(self.all)
    }
}

impl Bindings {
    /// The shift of register class `class` (`b`, `t`, `u`, `s`) in `space`.
    pub fn shift(&self, class: char, space: u32) -> u32 {
        match class {
            'b' => self.b_shift.of(space),
            't' => self.t_shift.of(space),
            'u' => self.u_shift.of(space),
            's' => self.s_shift.of(space),
            _ => 0,
        }
    }

    /// Whether any register-mapping option was given: the project builds
    /// for Vulkan with a mapping of its own.
    pub fn any(&self) -> bool {
        *self != Bindings::default()
    }

    /// Where `-fvk-bind-register` puts `register(class index, space)`.
    pub fn bound_register(&self, class: char, index: u32, space: u32) -> Option<(u32, u32)> {
        self.bind_register
            .iter()
            .rev()
            .find(|r| r.class == class && r.index == index && r.space == space)
            .map(|r| (r.set, r.binding))
    }
}

impl Profile {
    /// Reads `ps_6_5`, `lib_6_x`, ...; `None` for anything else.
    pub fn parse(s: &str) -> Option<Profile> {
        let mut parts = s.split('_');
        let kind = match parts.next()? {
            "ps" => ProfileKind::Pixel,
            "vs" => ProfileKind::Vertex,
            "gs" => ProfileKind::Geometry,
            "hs" => ProfileKind::Hull,
            "ds" => ProfileKind::Domain,
            "cs" => ProfileKind::Compute,
            "lib" => ProfileKind::Library,
            "ms" => ProfileKind::Mesh,
            "as" => ProfileKind::Amplification,
            _ => return None,
        };
        let major: u32 = parts.next()?.parse().ok()?;
        let minor = match parts.next()? {
            "x" if kind == ProfileKind::Library => 15,
            m => m.parse().ok()?,
        };
        if parts.next().is_some() || major != 6 {
            return None;
        }
        Some(Profile { kind, major, minor })
    }
}

/// What [`parse_args`] read besides the options.
#[derive(Clone, Debug, Default)]
pub struct ParsedArgs {
    /// Arguments that are not DXC options (input files, the caller's own
    /// flags), in order.
    pub rest: Vec<String>,
    /// `-Fo FILE`.
    pub output: Option<PathBuf>,
    /// One line per accepted option that changes nothing here (`-O3`,
    /// `-Zi`, ...), for a verbose mode to print.
    pub notes: Vec<String>,
}

/// DXC options accepted without effect: what they do (optimize, validate,
/// embed debug info, pick the output kind) does not change what the module
/// means, or this compiler already does it.
const NO_OP_FLAGS: &[&str] = &[
    "-spirv",
    "-fcgl",
    "-O0",
    "-O1",
    "-O2",
    "-O3",
    "-Od",
    "-Vd",
    "-Zi",
    "-Qembed_debug",
    "-Qstrip_debug",
    "-Qstrip_reflect",
    "-Zss",
    "-Zsb",
    "-Ges",
    "-Gis",
    "-WX",
    "-no-warnings",
    "-nologo",
    "-all-resources-bound",
    "-res-may-alias",
    "-Gfa",
    "-Gfp",
    "-Vi",
    "-H",
    "-Cc",
    "-No",
    "-Ni",
    "-Lx",
    "-fspv-reflect",
    "-fspv-preserve-interface",
    "-fvk-use-dx-position-w",
    "-Wno-vk-ignored-features",
    "-Wno-vk-emulated-features",
    // Only vertex, geometry, domain and mesh shaders write `SV_Position`,
    // and this compiler compiles none of those.
    "-fvk-invert-y",
];

/// DXC options with one value that change nothing here (the value may be
/// joined, `-Fdfile`, or separate).
const NO_OP_WITH_VALUE: &[&str] = &["-Fd", "-Fe", "-Fc", "-Fh", "-Vn", "-Fre", "-Frs"];

/// Reads DXC's command line into `options`. Unknown arguments go to
/// [`ParsedArgs::rest`]; a DXC option with a bad value is an error naming
/// it. Options this compiler cannot honour (another layout rule, another
/// stage) are errors too, never silently ignored.
pub fn parse_args(args: &[String], options: &mut HlslOptions) -> Result<ParsedArgs, String> {
    let mut out = ParsedArgs::default();
    let mut i = 0;
    // The value of `-X VALUE` or `-XVALUE` for a short option `-X`.
    let value = |i: &mut usize, name: &str| -> Result<String, String> {
        let a = &args[*i];
        if a.len() > name.len() {
            return Ok(a[name.len()..].trim_start_matches('=').to_string());
        }
        *i += 1;
        args.get(*i)
            .cloned()
            .ok_or_else(|| format!("{name} needs a value"))
    };
    let number = |s: &str, what: &str| -> Result<u32, String> {
        s.parse::<u32>()
            .map_err(|_| format!("{what}: expected a number, not `{s}`"))
    };
    let mut saw_shift = false;
    while i < args.len() {
        let a = args[i].as_str();
        // DXC's Windows spellings (`/T ps_6_0`, `/D X=1`), taken only whole:
        // `/Data` may as well be a file.
        const SLASHED: &[&str] = &[
            "T",
            "E",
            "I",
            "D",
            "Fo",
            "HV",
            "Zi",
            "Zpr",
            "Zpc",
            "Od",
            "O0",
            "O1",
            "O2",
            "O3",
            "Vd",
            "WX",
            "Qembed_debug",
            "Ges",
            "Gis",
            "nologo",
        ];
        let a_owned;
        if a == "-spirv" || a.starts_with("-fspv-") || a.starts_with("-fvk-") || a == "-vkbr" {
            options.spirv = true;
        }
        let a = match a.strip_prefix('/') {
            Some(r) if SLASHED.contains(&r) => {
                a_owned = format!("-{r}");
                a_owned.as_str()
            }
            _ => a,
        };
        let at = i;
        let args_i = |k: usize| args.get(at + k).cloned();
        if NO_OP_FLAGS.contains(&a) || (a.starts_with("-W") && a.len() > 2) {
            // `-Wall`, `-Wno-conversion`, ...: warnings this compiler does not give.
            out.notes
                .push(format!("{a}: accepted, changes nothing here"));
        } else if let Some(n) = NO_OP_WITH_VALUE.iter().find(|n| a.starts_with(**n)) {
            let v = if a.len() > n.len() {
                a[n.len()..].to_string()
            } else {
                i += 1;
                args_i(1).ok_or_else(|| format!("{n} needs a value"))?
            };
            out.notes
                .push(format!("{n} {v}: accepted, changes nothing here"));
        } else if a == "-Fo" || (a.starts_with("-Fo") && a.len() > 3) {
            out.output = Some(PathBuf::from(value(&mut i, "-Fo")?));
        } else if a == "-E" || (a.starts_with("-E") && a.len() > 2 && !a.starts_with("-enable")) {
            options.entry = Some(value(&mut i, "-E")?);
        } else if a == "-T" || (a.starts_with("-T") && a.len() > 2) {
            let t = value(&mut i, "-T")?;
            options.stage = crate::parse_stage(&t).map_err(|e| format!("-T: {e}"))?;
            options.profile = Profile::parse(&t);
        } else if a == "-I" || (a.starts_with("-I") && a.len() > 2) {
            options
                .include_dirs
                .push(PathBuf::from(value(&mut i, "-I")?));
        } else if a == "-D" || (a.starts_with("-D") && a.len() > 2) {
            let d = value(&mut i, "-D")?;
            options.defines.push(match d.split_once('=') {
                Some((n, v)) => (n.to_string(), v.to_string()),
                None => (d, "1".to_string()),
            });
        } else if a == "-HV" {
            let v = value(&mut i, "-HV")?;
            options.hlsl_version = Some(match v.as_str() {
                "2016" | "2017" | "2018" | "2021" => number(&v, "-HV")?,
                "202x" => 2029,
                _ => {
                    return Err(format!(
                        "-HV: unknown HLSL version `{v}` (2016, 2017, 2018, 2021 or 202x)"
                    ))
                }
            });
        } else if a == "-enable-16bit-types" {
            options.enable_16bit_types = true;
        } else if a == "-Zpr" {
            options.row_major = true;
        } else if a == "-Zpc" {
            options.row_major = false;
        } else if let Some(env) = a.strip_prefix("-fspv-target-env=") {
            options.target_env = TargetEnv::parse(env).ok_or_else(|| {
                format!("-fspv-target-env: unknown environment `{env}` (vulkan1.0, vulkan1.1, vulkan1.1spirv1.4, vulkan1.2, vulkan1.3, universal1.5)")
            })?;
        } else if let Some(ext) = a.strip_prefix("-fspv-extension=") {
            out.notes.push(format!(
                "-fspv-extension={ext}: accepted; the module uses the extensions its code needs"
            ));
        } else if let Some(d) = a.strip_prefix("-fspv-debug=") {
            out.notes.push(format!(
                "-fspv-debug={d}: accepted; the module always carries full debug info"
            ));
        } else if a.starts_with("-fspv-debug") {
            return Err(format!("{a}: expected -fspv-debug=<category>"));
        } else if a == "-fvk-use-gl-layout"
            || a == "-fvk-use-dx-layout"
            || a == "-fvk-use-scalar-layout"
        {
            return Err(format!(
                "not supported: {a} (this compiler lays buffers out by DXC's default rules only)"
            ));
        } else if let Some(class) = a
            .strip_prefix("-fvk-")
            .and_then(|r| r.strip_suffix("-shift"))
            .filter(|c| matches!(*c, "b" | "t" | "u" | "s"))
        {
            saw_shift = true;
            let n = number(&args_i(1).ok_or_else(|| format!("{a} needs N SPACE"))?, a)?;
            let space = args_i(2).ok_or_else(|| format!("{a} needs N SPACE"))?;
            i += 2;
            let b = &mut options.bindings;
            let shift = match class {
                "b" => &mut b.b_shift,
                "t" => &mut b.t_shift,
                "u" => &mut b.u_shift,
                _ => &mut b.s_shift,
            };
            if space == "all" {
                if !shift.per_space.is_empty() {
                    return Err(format!("{a}: `all` must be used alone"));
                }
                shift.all = n;
            } else {
                if shift.all != 0 {
                    return Err(format!("{a}: `all` must be used alone"));
                }
                shift.per_space.push((number(&space, a)?, n));
            }
        } else if a == "-fvk-bind-register" || a == "-vkbr" {
            let vals: Vec<String> = (1..=4)
                .map(|k| args_i(k).ok_or_else(|| format!("{a} needs xN SPACE BINDING SET")))
                .collect::<Result<_, _>>()?;
            i += 4;
            let reg = &vals[0];
            let class = reg
                .chars()
                .next()
                .filter(|c| matches!(c, 'b' | 't' | 'u' | 's'))
                .ok_or_else(|| format!("{a}: expected a register such as t0, not `{reg}`"))?;
            options.bindings.bind_register.push(RegisterBinding {
                class,
                index: number(&reg[1..], a)?,
                space: number(&vals[1], &format!("{a} space"))?,
                binding: number(&vals[2], &format!("{a} binding"))?,
                set: number(&vals[3], &format!("{a} set"))?,
            });
        } else if a == "-fvk-bind-globals" {
            let b = args_i(1).ok_or_else(|| format!("{a} needs BINDING SET"))?;
            let s = args_i(2).ok_or_else(|| format!("{a} needs BINDING SET"))?;
            i += 2;
            options.bindings.bind_globals = Some((
                number(&b, "-fvk-bind-globals binding")?,
                number(&s, "-fvk-bind-globals set")?,
            ));
        } else if a == "-fvk-auto-shift-bindings" {
            options.bindings.auto_shift = true;
        } else if a == "-auto-binding-space" {
            let v = value(&mut i, a)?;
            options.bindings.default_space = number(&v, a)?;
        } else {
            out.rest.push(args[i].clone());
        }
        i += 1;
    }
    // DXC's default entry point for a stage's profile.
    if options.entry.is_none() && options.stage.is_some() {
        options.entry = Some("main".to_string());
    }
    if saw_shift && !options.bindings.bind_register.is_empty() {
        return Err("-fvk-*-shift cannot be used together with -fvk-bind-register".to_string());
    }
    Ok(out)
}

impl HlslOptions {
    /// These options, then `later`'s on top (a project's defaults, then a
    /// command line): lists are appended, what `later` sets wins.
    pub fn merge(&mut self, later: &HlslOptions) {
        self.include_dirs.extend(later.include_dirs.iter().cloned());
        self.defines.extend(later.defines.iter().cloned());
        if later.entry.is_some() {
            self.entry = later.entry.clone();
        }
        if later.stage.is_some() {
            self.stage = later.stage;
        }
        if later.profile.is_some() {
            self.profile = later.profile;
        }
        self.enable_16bit_types |= later.enable_16bit_types;
        if later.hlsl_version.is_some() {
            self.hlsl_version = later.hlsl_version;
        }
        self.row_major |= later.row_major;
        if later.target_env != TargetEnv::default() {
            self.target_env = later.target_env;
        }
        let (b, l) = (&mut self.bindings, &later.bindings);
        for (mine, theirs) in [
            (&mut b.b_shift, &l.b_shift),
            (&mut b.t_shift, &l.t_shift),
            (&mut b.u_shift, &l.u_shift),
            (&mut b.s_shift, &l.s_shift),
        ] {
            if theirs.all != 0 {
                *mine = theirs.clone();
            } else {
                mine.per_space.extend(theirs.per_space.iter().copied());
            }
        }
        b.bind_register.extend(l.bind_register.iter().copied());
        if l.bind_globals.is_some() {
            b.bind_globals = l.bind_globals;
        }
        b.auto_shift |= l.auto_shift;
        if l.default_space != 0 {
            b.default_space = l.default_space;
        }
        self.spirv |= later.spirv;
    }

    /// The macros DXC defines before the user's `-D`s, with its values for
    /// these options (a compile for Vulkan: `-spirv`).
    pub fn predefined_macros(&self) -> Vec<(&'static str, String)> {
        // The release whose behaviour this compiler follows (DXC 1.9.2607).
        const DXC_VERSION: [u32; 4] = [1, 9, 2607, 0];
        let profile = self.profile.unwrap_or(match self.stage {
            Some(Stage::Fragment) => Profile {
                kind: ProfileKind::Pixel,
                major: 6,
                minor: 5,
            },
            Some(Stage::Compute) => Profile {
                kind: ProfileKind::Compute,
                major: 6,
                minor: 5,
            },
            _ => Profile {
                kind: ProfileKind::Library,
                major: 6,
                minor: 5,
            },
        });
        let (spv_major, spv_minor) = self.target_env.spirv_version();
        let mut m = vec![
            ("__hlsl_dx_compiler", "1".to_string()),
            ("__DXC_VERSION_MAJOR", DXC_VERSION[0].to_string()),
            ("__DXC_VERSION_MINOR", DXC_VERSION[1].to_string()),
            ("__DXC_VERSION_RELEASE", DXC_VERSION[2].to_string()),
            ("__DXC_VERSION_COMMITS", DXC_VERSION[3].to_string()),
            (
                "__HLSL_VERSION",
                self.hlsl_version.unwrap_or(2021).to_string(),
            ),
        ];
        if self.enable_16bit_types {
            m.push(("__HLSL_ENABLE_16_BIT", "1".to_string()));
        }
        use ProfileKind as K;
        for (name, kind) in [
            ("__SHADER_STAGE_VERTEX", K::Vertex),
            ("__SHADER_STAGE_PIXEL", K::Pixel),
            ("__SHADER_STAGE_GEOMETRY", K::Geometry),
            ("__SHADER_STAGE_HULL", K::Hull),
            ("__SHADER_STAGE_DOMAIN", K::Domain),
            ("__SHADER_STAGE_COMPUTE", K::Compute),
            ("__SHADER_STAGE_AMPLIFICATION", K::Amplification),
            ("__SHADER_STAGE_MESH", K::Mesh),
            ("__SHADER_STAGE_LIBRARY", K::Library),
        ] {
            m.push((name, (kind as u32).to_string()));
        }
        m.push(("__SHADER_TARGET_STAGE", (profile.kind as u32).to_string()));
        m.push(("__SHADER_TARGET_MAJOR", profile.major.to_string()));
        m.push(("__SHADER_TARGET_MINOR", profile.minor.to_string()));
        m.push(("__spirv__", "1".to_string()));
        m.push(("__SPIRV_MAJOR_VERSION__", spv_major.to_string()));
        m.push(("__SPIRV_MINOR_VERSION__", spv_minor.to_string()));
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(line: &str) -> Result<(HlslOptions, ParsedArgs), String> {
        let args: Vec<String> = line.split_whitespace().map(String::from).collect();
        let mut o = HlslOptions::default();
        parse_args(&args, &mut o).map(|p| (o, p))
    }

    #[test]
    fn reads_a_dxc_command_line() {
        let (o, p) = parse(
            "-spirv -T lib_6_3 -HV 2021 -fspv-target-env=vulkan1.2 -O3 -Zi -Iinc -I other \
             -DA=2 -D B -fvk-t-shift 1000 all -fvk-u-shift 2000 0 -fvk-u-shift 3000 1 \
             -fvk-auto-shift-bindings -fvk-bind-globals 5 2 -Fo out.spv rt.hlsl --verbose",
        )
        .unwrap();
        assert_eq!(p.rest, ["rt.hlsl", "--verbose"]);
        assert_eq!(p.output, Some(PathBuf::from("out.spv")));
        assert_eq!(p.notes.len(), 3, "{:?}", p.notes);
        assert_eq!(o.stage, None);
        assert_eq!(o.profile.unwrap().minor, 3);
        assert_eq!(
            o.include_dirs,
            [PathBuf::from("inc"), PathBuf::from("other")]
        );
        assert_eq!(
            o.defines,
            [("A".into(), "2".into()), ("B".into(), "1".into())]
        );
        assert_eq!(o.target_env, TargetEnv::Vulkan1_2);
        let b = &o.bindings;
        assert_eq!(
            (b.shift('t', 7), b.shift('u', 0), b.shift('u', 1)),
            (1000, 2000, 3000)
        );
        assert_eq!((b.shift('u', 2), b.shift('b', 0)), (0, 0));
        assert!(b.auto_shift);
        assert_eq!(b.bind_globals, Some((5, 2)));
    }

    #[test]
    fn windows_spellings_and_paths() {
        let (o, p) = parse("/T ps_6_0 /E main /D X=1 /Zi /Data /Engine.hlsl").unwrap();
        assert_eq!(o.entry.as_deref(), Some("main"));
        assert_eq!(o.defines, [("X".into(), "1".into())]);
        assert_eq!(p.rest, ["/Data", "/Engine.hlsl"]);
    }

    #[test]
    fn refuses_bad_values_and_mixes() {
        assert!(parse("-fvk-t-shift x 0")
            .unwrap_err()
            .contains("-fvk-t-shift"));
        assert!(parse("-fvk-t-shift 1 all -fvk-t-shift 2 0").is_err());
        assert!(parse("-fvk-b-shift 1 0 -fvk-bind-register t0 0 1 2").is_err());
        assert!(parse("-HV 2019").is_err());
        assert!(parse("-fvk-use-scalar-layout")
            .unwrap_err()
            .starts_with("not supported"));
        assert!(parse("-T vs_6_0").is_err());
    }

    #[test]
    fn lib_6_x_and_stage_macros() {
        let (o, _) = parse("-T lib_6_x").unwrap();
        let m = o.predefined_macros();
        let get = |n: &str| m.iter().find(|(k, _)| *k == n).unwrap().1.clone();
        assert_eq!(get("__SHADER_TARGET_MINOR"), "15");
        assert_eq!(get("__SHADER_TARGET_STAGE"), get("__SHADER_STAGE_LIBRARY"));
        let (o, _) = parse("-E main -T ps_6_0 -HV 202x").unwrap();
        let m = o.predefined_macros();
        let get = |n: &str| m.iter().find(|(k, _)| *k == n).unwrap().1.clone();
        assert_eq!(get("__SHADER_TARGET_STAGE"), "0");
        assert_eq!(get("__SHADER_TARGET_MINOR"), "0");
        assert_eq!(get("__HLSL_VERSION"), "2029");
        assert_eq!(get("__SPIRV_MAJOR_VERSION__"), "1");
        assert_eq!(get("__SPIRV_MINOR_VERSION__"), "0");
    }
}
