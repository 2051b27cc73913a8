//! Every struct the host writes into a buffer the WGSL reads as a struct, held to the WGSL's
//! declaration of the same name in one table: the WGSL struct is parsed from the shader source,
//! its layout computed by WGSL's rules (each member at the next multiple of its alignment;
//! scalars 4 bytes, `vec2` 8, `vec3` 12 aligned to 16, `vec4` 16; the struct's size rounded up to
//! its largest alignment), and every member's offset, in order, and the size compared with the
//! Rust struct's `offset_of!` and `size_of`. A member added, removed, reordered or retyped on one
//! side, or a struct renamed on one side, fails here.

use std::mem::{offset_of, size_of};

use crate::merl_lookup::{MerlDimsUniform, MerlDirPair, MerlSample};
use crate::preview::adaptive::{AdaptivePass, RecordLobe, RecordSurface};
use crate::preview::present::PresentUniform;
use crate::preview::uniforms::{FrameUniform, PredictUniform, ShadeUniform, WaveletUniform};
use crate::wgsl::{
    ADAPTIVE_PREDICT, ADAPTIVE_STATE, MERL_LOOKUP, MERL_LOOKUP_BATCH, PREVIEW_BINDINGS, PREVIEW_PRESENT, WAVELET_BRDF,
};

/// A host struct: the WGSL source that declares the struct of the same name, its size, and its
/// members' WGSL names with their Rust offsets, in order (a nested Rust struct's members flattened, as the WGSL has
/// them).
struct Shared {
    wgsl: &'static str,
    name: &'static str,
    size: usize,
    members: Vec<(&'static str, usize)>,
}

macro_rules! shared {
    ($wgsl:expr, $ty:ident { $($member:literal => $($field:ident).+),* $(,)? }) => {
        Shared {
            wgsl: $wgsl,
            name: stringify!($ty),
            size: size_of::<$ty>(),
            members: vec![$(($member, offset_of!($ty, $($field).+))),*],
        }
    };
}

/// Size and alignment of a WGSL member type (the types the shared structs use).
fn size_align(ty: &str) -> (usize, usize) {
    match ty {
        "u32" | "i32" | "f32" => (4, 4),
        "vec2<u32>" | "vec2<i32>" | "vec2<f32>" => (8, 8),
        "vec3<u32>" | "vec3<i32>" | "vec3<f32>" => (12, 16),
        "vec4<u32>" | "vec4<i32>" | "vec4<f32>" => (16, 16),
        other => panic!("a member type the layout test does not know: {other}"),
    }
}

/// The members of WGSL struct `name` in `source` with their offsets, and the struct's size.
fn wgsl_layout(source: &str, name: &str) -> (Vec<(String, usize)>, usize) {
    let start = source.find(&format!("struct {name} {{")).unwrap_or_else(|| panic!("no WGSL struct {name}"));
    let body = &source[start..];
    let body = &body[body.find('{').unwrap() + 1..body.find('}').unwrap()];
    let (mut offset, mut largest) = (0usize, 1usize);
    let mut members = Vec::new();
    for line in body.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with("//")) {
        let (member, ty) = line.trim_end_matches(',').split_once(':').unwrap_or_else(|| panic!("{name}: {line:?}"));
        let (size, align) = size_align(ty.trim());
        offset = offset.next_multiple_of(align);
        members.push((member.trim().to_string(), offset));
        offset += size;
        largest = largest.max(align);
    }
    (members, offset.next_multiple_of(largest))
}

fn shared_structs() -> Vec<Shared> {
    vec![
        shared!(MERL_LOOKUP.source, MerlDimsUniform {
            "n_theta_h" => n_theta_h, "n_theta_d" => n_theta_d, "n_phi_d" => n_phi_d, "phi_d_range" => phi_d_range,
        }),
        shared!(MERL_LOOKUP_BATCH.source, MerlDirPair { "wi" => wi, "wo" => wo }),
        shared!(MERL_LOOKUP_BATCH.source, MerlSample { "rgb" => rgb, "cell" => cell }),
        shared!(WAVELET_BRDF.source, WaveletUniform {
            "side" => side, "levels" => levels, "enabled" => enabled, "lod" => lod, "mean" => mean,
            "epsilon" => epsilon,
        }),
        shared!(PREVIEW_BINDINGS.source, ShadeUniform {
            "eye" => eye, "ray_forward" => ray_forward, "ray_right" => ray_right, "ray_up" => ray_up,
            "width" => width, "height" => height, "seed" => seed, "mode" => mode, "spp" => spp,
            "n_slices" => n_slices, "n_vectors" => n_vectors, "n_samples" => n_samples, "n_levels" => n_levels,
            "n_view_rows" => n_view_rows, "n_layers" => n_layers, "layer_shift" => layer_shift,
            "mips_first" => maps.mips_first, "layers_first" => maps.layers_first, "peak_map" => maps.peak_map, "map_records" => maps.records,
            "brdf_rows" => tables.brdf_rows, "brdf_sectors" => tables.brdf_sectors, "t_edges" => tables.t_edges,
            "brdf_marginal" => tables.brdf_marginal, "brdf_conditional" => tables.brdf_conditional,
            "env_marginal" => tables.env_marginal, "env_conditional" => tables.env_conditional,
            "peak_marginal" => tables.peak_marginal, "peak_conditional" => tables.peak_conditional, "view_layers" => tables.view_layers,
            "items" => items, "filter_samples" => filter_samples, "diffuse" => diffuse,
        }),
        shared!(PREVIEW_BINDINGS.source, FrameUniform { "index" => index }),
        shared!(ADAPTIVE_STATE.source, RecordSurface {
            "depth" => depth, "cos_o" => cos_o, "screen_normal" => screen_normal,
        }),
        shared!(ADAPTIVE_STATE.source, RecordLobe { "mirror" => mirror, "prediction" => prediction }),
        shared!(ADAPTIVE_PREDICT.source, PredictUniform {
            "n_b" => n_b, "env_width" => env_width, "env_height" => env_height, "lobes_x" => lobes_x,
            "lobes_y" => lobes_y, "tile" => tile, "radians_per_pixel" => radians_per_pixel, "_pad" => _pad,
        }),
        shared!(ADAPTIVE_STATE.source, AdaptivePass {
            "level" => level, "top" => top, "width" => width, "height" => height, "out_width" => out_width,
            "out_height" => out_height, "ss" => ss, "count" => count, "level_table" => level_table,
            "sharpness" => sharpness, "n_rows" => n_rows, "oracle" => oracle, "depth_sigma" => depth_sigma,
            "rescue_below" => rescue_below, "candidates" => candidates, "budget" => budget, "max_spp" => max_spp,
            "capacity" => capacity, "allocate" => allocate, "_pad" => _pad,
        }),
        shared!(PREVIEW_PRESENT.source, PresentUniform {
            "image_size" => image_size, "frames" => frames, "view" => view, "exposure" => exposure,
            "srgb_target" => srgb_target, "n_indices" => n_indices, "_pad" => _pad, "origin" => origin,
            "scale" => scale, "_pad2" => _pad2,
        }),
    ]
}

#[test]
fn every_struct_shared_with_the_wgsl_has_its_layout() {
    let mut failures = Vec::new();
    for shared in shared_structs() {
        let (wgsl, size) = wgsl_layout(shared.wgsl, shared.name);
        let host: Vec<(String, usize)> = shared.members.iter().map(|(m, o)| (m.to_string(), *o)).collect();
        if wgsl != host || size != shared.size {
            failures.push(format!(
                "{}: the WGSL's members {wgsl:?} ({size} bytes), the host's {host:?} ({} bytes)",
                shared.name, shared.size
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The layout rules themselves, on a struct whose answer is known by hand: a `vec3` is aligned
/// to 16 and a scalar fills its fourth slot; the size rounds up to the largest alignment.
#[test]
fn the_wgsl_layout_rules_give_the_known_offsets() {
    let source = "struct S {\n  a: f32,\n  // a comment\n  b: vec3<f32>,\n  c: u32,\n  d: vec2<f32>,\n}";
    let (members, size) = wgsl_layout(source, "S");
    let expected = [("a", 0), ("b", 16), ("c", 28), ("d", 32)].map(|(m, o)| (m.to_string(), o));
    assert_eq!(members, expected);
    assert_eq!(size, 48);
}
