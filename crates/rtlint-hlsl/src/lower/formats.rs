//! Storage-image formats: `[[vk::image_format("...")]]` by DXC's names.

use super::*;

/// Applies `[[vk::image_format("name")]]` to a storage texture type.
pub(super) fn with_image_format(t: Ty, a: &Attr) -> Result<Ty> {
    let name = attr_str(a)
        .ok_or_else(|| Error::new(a.pos, "expected [[vk::image_format(\"format\")]]"))?;
    let format = image_format_named(name)
        .ok_or_else(|| Error::new(a.pos, format!("unknown image format \"{name}\"")))?;
    match t {
        Ty::Texture {
            dim,
            sc,
            n,
            rw: true,
            ..
        } => Ok(Ty::Texture {
            dim,
            sc,
            n,
            rw: true,
            fmt: Some(format),
        }),
        _ => Err(unsupported(
            a.pos,
            "`vk::image_format` on anything but an RWTexture",
        )),
    }
}

/// DXC's names for `vk::image_format`.
fn image_format_named(name: &str) -> Option<spirv::ImageFormat> {
    use spirv::ImageFormat as F;
    Some(match name {
        "unknown" => F::Unknown,
        "rgba32f" => F::Rgba32f,
        "rgba16f" => F::Rgba16f,
        "r32f" => F::R32f,
        "rgba8" => F::Rgba8,
        "rgba8snorm" => F::Rgba8Snorm,
        "rg32f" => F::Rg32f,
        "rg16f" => F::Rg16f,
        "r11g11b10f" => F::R11fG11fB10f,
        "r16f" => F::R16f,
        "rgba16" => F::Rgba16,
        "rgb10a2" => F::Rgb10A2,
        "rg16" => F::Rg16,
        "rg8" => F::Rg8,
        "r16" => F::R16,
        "r8" => F::R8,
        "rgba16snorm" => F::Rgba16Snorm,
        "rg16snorm" => F::Rg16Snorm,
        "rg8snorm" => F::Rg8Snorm,
        "r16snorm" => F::R16Snorm,
        "r8snorm" => F::R8Snorm,
        "rgba32i" => F::Rgba32i,
        "rgba16i" => F::Rgba16i,
        "rgba8i" => F::Rgba8i,
        "r32i" => F::R32i,
        "rg32i" => F::Rg32i,
        "rg16i" => F::Rg16i,
        "rg8i" => F::Rg8i,
        "r16i" => F::R16i,
        "r8i" => F::R8i,
        "rgba32ui" => F::Rgba32ui,
        "rgba16ui" => F::Rgba16ui,
        "rgba8ui" => F::Rgba8ui,
        "r32ui" => F::R32ui,
        "rgb10a2ui" => F::Rgb10a2ui,
        "rg32ui" => F::Rg32ui,
        "rg16ui" => F::Rg16ui,
        "rg8ui" => F::Rg8ui,
        "r16ui" => F::R16ui,
        "r8ui" => F::R8ui,
        _ => return None,
    })
}
