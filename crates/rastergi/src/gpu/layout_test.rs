//! The one check of every Rust/WGSL twin: each composed shader is parsed with naga, and every
//! struct that Rust also lays out must have the Rust size and member offsets (`size_of`,
//! `offset_of!`), wherever it appears; the constants that [`crate::gpu::shader::constants`]
//! generates must hold the Rust values in every shader. Members whose names start with `_`
//! are padding on both sides and are matched by size alone.

use std::collections::{BTreeMap, BTreeSet};
use std::mem::{offset_of, size_of};
use std::path::Path;

use crate::gpu::binding::{Group, Kind};
use crate::gpu::structs::GpuStruct;

use crate::bvh::wide::WideNode;
use crate::environment::GpuEnvironment;
use crate::gather::GatherUniforms;
use crate::gpu_scene::{GpuMaterial, GpuMaterialMaps, GpuTextureSlot, GpuTriangle};
use crate::lights::{LightEntry, PunctualLight};
use crate::passes::display::DisplayUniforms;
use crate::passes::film::ResolveUniforms;
use crate::passes::frame::FrameUniforms;
use crate::path_tracer::PathParams;
use crate::photons::gpu::{GridLevels, PhotonGridUniforms, PhotonParams};
use crate::photons::map::TrianglePlane;

/// A Rust struct and the name of its WGSL twin.
struct Twin {
    rust: &'static str,
    wgsl: &'static str,
    size: usize,
    /// The non-padding fields and their offsets.
    fields: Vec<(&'static str, usize)>,
}

macro_rules! twin {
    ($rust:ty, $wgsl:literal, [$($field:ident),* $(,)?]) => {
        Twin {
            rust: stringify!($rust),
            wgsl: $wgsl,
            size: size_of::<$rust>(),
            fields: vec![$((stringify!($field), offset_of!($rust, $field))),*],
        }
    };
}

/// The twin of a struct declared once by [`crate::gpu::structs::gpu_struct!`]: its generated WGSL
/// declaration is checked as a hand-written one would be.
fn generated<T: GpuStruct>() -> Twin {
    let members = T::members().into_iter().filter(|m| m.pad_lanes == 0);
    Twin {
        rust: std::any::type_name::<T>(),
        wgsl: T::WGSL_NAME,
        size: size_of::<T>(),
        fields: members.map(|m| (m.name, m.offset)).collect(),
    }
}

fn twins() -> Vec<Twin> {
    vec![
        generated::<FrameUniforms>(),
        generated::<GpuEnvironment>(),
        generated::<GpuTriangle>(),
        generated::<crate::gpu_scene::GpuMaterialRecord>(),
        generated::<GpuTextureSlot>(),
        generated::<crate::textures::AtlasEntry>(),
        generated::<GpuMaterial>(),
        generated::<GpuMaterialMaps>(),
        generated::<WideNode>(),
        generated::<LightEntry>(),
        generated::<PunctualLight>(),
        generated::<GatherUniforms>(),
        generated::<PhotonParams>(),
        generated::<PhotonGridUniforms>(),
        generated::<GridLevels>(),
        generated::<ResolveUniforms>(),
        generated::<crate::passes::denoise::DenoiseUniforms>(),
        generated::<DisplayUniforms>(),
        generated::<TrianglePlane>(),
        generated::<PathParams>(),
        generated::<crate::photons::budget::BudgetUniforms>(),
        twin!(crate::bsdf::albedo::GpuGgxAlbedo, "GgxAlbedoTable", [cells, means, glass]),
        twin!(crate::rays::GpuRay, "Ray", [origin, dir, skip_any]),
        twin!(crate::rays::GpuRayHit, "RayHit", [t, tri, b1, b2]),
    ]
}

/// Every shader rastergi builds, composed as its pass composes it.
fn shaders() -> Vec<(&'static str, String)> {
    use crate::gather::estimator::{RAY_VIEW_LOOKUP, estimate_source};
    vec![
        ("gbuffer", crate::passes::gbuffer::source()),
        ("gbuffer trace", crate::passes::gbuffer::trace_source()),
        ("direct", crate::passes::direct::source()),
        ("direct with photon map", crate::passes::direct::source_with_map()),
        ("gather guide build", crate::gather::guide::build_source()),
        ("specular chains", crate::passes::specular::source()),
        ("photon view", crate::passes::photon_view::source()),
        ("gather ray view", crate::gather::ray_view::ray_view_source()),
        ("gather project", estimate_source(&[RAY_VIEW_LOOKUP, include_str!("../gather/raster.wgsl")])),
        ("gather list project", estimate_source(&[RAY_VIEW_LOOKUP, include_str!("../gather/lists.wgsl")])),
        ("gather trace", estimate_source(&[include_str!("../gather/trace.wgsl")])),
        ("photon trace", crate::photons::gpu::trace_source()),
        ("resolve", crate::passes::film::resolve_source()),
        ("film half", include_str!("../passes/film_half.wgsl").to_string()),
        ("photon budget", crate::photons::budget::source()),
        ("denoiser guides", crate::passes::denoise::guides_source()),
        ("denoiser", crate::passes::denoise::filter_source()),
        ("display", crate::passes::display::source()),
        ("path tracer", crate::path_tracer::source()),
        ("rays", crate::rays::source()),
    ]
}

/// A struct's members: (name, offset, size).
type Members = Vec<(String, u32, u32)>;

/// The structs of `module` by name: size and members.
fn structs(module: &naga::Module) -> BTreeMap<String, (u32, Members)> {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).expect("layouts of a parsed module");
    let mut out = BTreeMap::new();
    for (_, ty) in module.types.iter() {
        if let (Some(name), naga::TypeInner::Struct { members, span }) = (&ty.name, &ty.inner) {
            let members =
                members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset, layouter[m.ty].size)).collect();
            out.insert(name.clone(), (*span, members));
        }
    }
    out
}

/// The u32 constants of `module` by name.
fn u32_constants(module: &naga::Module) -> BTreeMap<String, u32> {
    let mut out = BTreeMap::new();
    for (_, c) in module.constants.iter() {
        if let (Some(name), naga::Expression::Literal(naga::Literal::U32(v))) =
            (&c.name, &module.global_expressions[c.init])
        {
            out.insert(name.clone(), *v);
        }
    }
    out
}

#[test]
fn every_rust_wgsl_twin_has_the_same_size_and_offsets_in_every_shader() {
    let twins = twins();
    let mut seen: BTreeMap<&str, usize> = BTreeMap::new();
    for (label, source) in shaders() {
        let module =
            naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{label}: {}", e.emit_to_string(&source)));
        let structs = structs(&module);
        for twin in &twins {
            let Some((span, members)) = structs.get(twin.wgsl) else { continue };
            *seen.entry(twin.rust).or_default() += 1;
            let at = format!("{} ↔ {} in the {label} shader", twin.rust, twin.wgsl);
            assert_eq!(*span as usize, twin.size, "{at}: size");
            let named: Vec<&(String, u32, u32)> = members.iter().filter(|m| !m.0.starts_with('_')).collect();
            for (name, offset, _) in &named {
                let rust = twin.fields.iter().find(|f| f.0 == name.as_str());
                let rust = rust.unwrap_or_else(|| panic!("{at}: WGSL member {name} has no Rust field"));
                assert_eq!(*offset as usize, rust.1, "{at}: offset of {name}");
            }
            for (field, _) in &twin.fields {
                assert!(named.iter().any(|m| m.0 == *field), "{at}: Rust field {field} has no WGSL member");
            }
        }
    }
    for twin in &twins {
        assert!(seen.contains_key(twin.rust), "{} ↔ {}: in no shader", twin.rust, twin.wgsl);
    }
}

#[test]
fn every_shader_holds_the_rust_constants() {
    // The generated declarations, parsed back: what every composed shader must hold.
    let generated = crate::gpu::shader::constants();
    let expected = u32_constants(&naga::front::wgsl::parse_str(&generated).expect("the generated constants parse"));
    assert!(expected.len() >= 9, "{expected:?}");
    assert_eq!(expected["MAX_DIRECTIONS"], crate::gather::MAX_DIRECTIONS);
    assert_eq!(expected["NO_TEXTURE"], crate::gpu_scene::NO_TEXTURE);
    assert_eq!(expected["STREAM_PHOTON"], crate::sampling::stream::PHOTON);
    for (label, source) in shaders() {
        if label == "display" || label == "film half" {
            continue; // draws an image, sums the film: no shared constant
        }
        let module =
            naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{label}: {}", e.emit_to_string(&source)));
        let constants = u32_constants(&module);
        for (name, value) in &expected {
            assert_eq!(constants.get(name), Some(value), "{label}: {name}");
        }
    }
}

/// Every shader that traces, composed for the hardware ray path (`shader::for_rays`), parses
/// and validates with naga: the ray query's `traverse` in place of the BVH walk, the TLAS at
/// its binding, the compute BVH's nodes no longer read by `traverse`.
#[test]
fn every_tracing_shader_composes_and_validates_for_hardware_ray_queries() {
    use crate::gpu::accel::{RayPath, TLAS_BINDING};
    let mut traced = Vec::new();
    for (label, source) in shaders() {
        let hardware = crate::gpu::shader::for_rays(&source, RayPath::Hardware, None);
        if hardware == source {
            continue;
        }
        traced.push(label);
        assert!(!hardware.contains("fn node_corners"), "{label}: the compute traversal is still there");
        let module = naga::front::wgsl::parse_str(&hardware)
            .unwrap_or_else(|e| panic!("{label} (hardware): {}", e.emit_to_string(&hardware)));
        let tlas = naga::ResourceBinding { group: 0, binding: TLAS_BINDING };
        assert!(module.global_variables.iter().any(|(_, g)| g.binding == Some(tlas)), "{label}: no TLAS binding");
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{label} (hardware): {}", e.emit_to_string(&hardware)));
        // And with its rays counted (`--count-rays`): the counter at its binding, `trace`
        // adding to it.
        let counted = crate::gpu::shader::for_rays(&source, RayPath::Hardware, Some(crate::gpu_scene::RayUse::Photons));
        let module = naga::front::wgsl::parse_str(&counted)
            .unwrap_or_else(|e| panic!("{label} (counted): {}", e.emit_to_string(&counted)));
        let count = naga::ResourceBinding { group: 0, binding: crate::gpu_scene::RAY_COUNT_BINDING };
        assert!(module.global_variables.iter().any(|(_, g)| g.binding == Some(count)), "{label}: no ray count");
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{label} (counted): {}", e.emit_to_string(&counted)));
    }
    // Every pass that casts rays (the G-buffer's raster shader holds the prelude too).
    let expected = [
        "gbuffer",
        "gbuffer trace",
        "direct",
        "direct with photon map",
        "specular chains",
        "photon view",
        "gather project",
        "gather list project",
        "gather trace",
    ];
    let expected = expected.into_iter().chain(["photon trace", "denoiser guides", "path tracer", "rays"]);
    assert_eq!(traced, expected.collect::<Vec<_>>());
}

/// The WGSL entry points (`@compute`, `@vertex`, `@fragment`) of every file under `src/`, as
/// (file relative to `src/`, function name).
fn entry_points_in_the_code() -> BTreeSet<(String, String)> {
    fn walk(dir: &Path, root: &Path, out: &mut BTreeSet<(String, String)>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, root, out);
            } else if path.extension().is_some_and(|e| e == "wgsl") {
                let text = std::fs::read_to_string(&path).unwrap();
                let file = path.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/");
                let mut pending = false;
                for line in text.lines().map(str::trim) {
                    if line.starts_with("//") {
                        continue;
                    }
                    pending |= ["@compute", "@vertex", "@fragment"].iter().any(|a| line.contains(a));
                    if pending && let Some(rest) = line.split_once("fn ").map(|(_, r)| r) {
                        let name = rest.split('(').next().unwrap().trim().to_owned();
                        out.insert((file.clone(), name));
                        pending = false;
                    }
                }
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut out = BTreeSet::new();
    walk(&root, &root, &mut out);
    out
}

/// The entry points docs/design.md's "Where each pass lives" names: cells of the form
/// `` `file.wgsl`: `a`, `b` ``.
fn entry_points_in_the_design_page() -> BTreeSet<(String, String)> {
    let design = include_str!("../../../../docs/design.md");
    let section = design.split("## Where each pass lives").nth(1).expect("the section").split("\n## ").next().unwrap();
    let mut out = BTreeSet::new();
    for cell in section.lines().filter(|l| l.starts_with('|')).flat_map(|l| l.split('|')) {
        if let Some((file, entries)) = cell.trim().split_once(".wgsl`:") {
            let file = format!("{}.wgsl", file.trim_start_matches('`'));
            for e in entries.split(',') {
                out.insert((file.clone(), e.trim().trim_matches('`').to_owned()));
            }
        }
    }
    out
}

#[test]
fn the_design_page_names_every_wgsl_entry_point_and_each_exists() {
    let (code, page) = (entry_points_in_the_code(), entry_points_in_the_design_page());
    assert!(code.len() >= 20, "the scan found only {code:?}");
    let missing: Vec<_> = code.difference(&page).collect();
    let stale: Vec<_> = page.difference(&code).collect();
    assert!(missing.is_empty(), "entry points docs/design.md does not name: {missing:?}");
    assert!(stale.is_empty(), "docs/design.md names entry points the code lacks: {stale:?}");
}

/// The bind groups each shader of [`shaders`] is built with, by group index; where one module
/// serves several pipelines, each group index lists the alternatives (the ray view's count,
/// peel and fill; the photon shader's trace and resolve).
fn declared_groups(label: &str) -> Vec<Vec<Group>> {
    use crate::passes::{denoise, film, frame, gbuffer};
    use crate::{gather, gpu_scene, photons};
    let scene = || vec![gpu_scene::group(false, false)];
    let per_pixel = || vec![scene(), vec![frame::group()], vec![gbuffer::pixel_group()]];
    let lookup = || vec![photons::gpu::lookup_group()];
    let estimate = |own: Group| vec![scene(), vec![frame::group()], vec![own], lookup()];
    match label {
        "gbuffer" => vec![scene(), vec![frame::group()]],
        "gbuffer trace" => vec![scene(), vec![frame::group()], vec![gbuffer::trace_group()]],
        "direct" | "specular chains" => per_pixel(),
        "photon view" | "direct with photon map" => [per_pixel(), vec![lookup()]].concat(),
        "gather guide build" => vec![vec![gather::guide::build_group()]],
        "gather ray view" => vec![
            scene(),
            vec![gather::raster::count_group(), gather::raster::peel_group(), gather::lists::fill_group()],
        ],
        "gather project" => estimate(gather::raster::project_group()),
        "gather list project" => estimate(gather::lists::project_group()),
        "gather trace" => estimate(gather::trace::group()),
        "photon trace" => vec![scene(), vec![photons::gpu::trace_group(), photons::gpu::resolve_group()]],
        "resolve" => vec![vec![film::resolve_group()]],
        "film half" => vec![vec![film::half_group()]],
        "photon budget" => vec![vec![photons::budget::group()]],
        "denoiser guides" => [per_pixel(), vec![vec![denoise::guides_group()]]].concat(),
        "denoiser" => vec![vec![denoise::filter_group()]],
        "display" => vec![vec![crate::passes::display::group()]],
        "path tracer" => vec![scene(), vec![frame::group()], vec![crate::path_tracer::group()]],
        "rays" => vec![scene(), vec![crate::rays::group()]],
        _ => panic!("shader {label}: its bind groups are not declared here"),
    }
}

/// What a WGSL global variable is, in the terms of a [`Slot`]'s [`Kind`] (`None`: something a
/// declaration cannot name).
fn wgsl_kind(module: &naga::Module, layouter: &naga::proc::Layouter, var: &naga::GlobalVariable) -> Option<Kind> {
    use naga::{AddressSpace, ImageClass, ImageDimension, ScalarKind, TypeInner};
    let size = |ty: naga::Handle<naga::Type>| match module.types[ty].inner {
        TypeInner::Array { base, .. } => layouter[base].size as u64,
        _ => layouter[ty].size as u64,
    };
    match (var.space, &module.types[var.ty].inner) {
        (AddressSpace::Uniform, _) => Some(Kind::Uniform { size: layouter[var.ty].size as u64 }),
        (AddressSpace::Storage { access }, _) => {
            Some(Kind::Storage { write: access.contains(naga::StorageAccess::STORE), size: size(var.ty) })
        }
        (
            AddressSpace::Handle,
            TypeInner::Image {
                dim: ImageDimension::D2,
                arrayed: false,
                class: ImageClass::Sampled { kind, multi: false },
            },
        ) => match kind {
            ScalarKind::Uint => Some(Kind::UintTexture),
            ScalarKind::Float => Some(Kind::FloatTexture),
            _ => None,
        },
        (
            AddressSpace::Handle,
            TypeInner::Image {
                dim: ImageDimension::D2,
                arrayed: false,
                class: ImageClass::Storage { format: naga::StorageFormat::Rgba32Uint, access },
            },
        ) if *access == naga::StorageAccess::STORE => Some(Kind::UintStorageTexture),
        (AddressSpace::Handle, TypeInner::AccelerationStructure { .. }) => Some(Kind::Tlas),
        _ => None,
    }
}

/// Every pass's declared bind groups ([`crate::gpu::binding`]) say what its shaders bind: each
/// WGSL binding is a declared slot of the same number, name, kind, access and element size,
/// and each declared slot is bound in the WGSL. A pass that reads or writes something it does
/// not declare, or declares what its shader lacks, fails here.
#[test]
fn every_declared_bind_group_matches_the_bindings_of_its_shaders() {
    let mut failures = Vec::new();
    // Each shader as composed for the compute ray path, and where it traces, for the hardware
    // one, whose scene group also binds the TLAS, and with its rays counted, whose scene group
    // also binds the count.
    let composed = |path: crate::gpu::accel::RayPath, count: bool| {
        shaders().into_iter().filter_map(move |(label, source)| {
            let used = count.then_some(crate::gpu_scene::RayUse::Gather);
            let s = crate::gpu::shader::for_rays(&source, path, used);
            (s != source).then(|| (label, s.into_owned(), (path == crate::gpu::accel::RayPath::Hardware, count)))
        })
    };
    let plain = shaders().into_iter().map(|(l, s)| (l, s, (false, false)));
    let variants = plain
        .chain(composed(crate::gpu::accel::RayPath::Hardware, false))
        .chain(composed(crate::gpu::accel::RayPath::Compute, true));
    for (label, source, (tlas, count)) in variants {
        let module = naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{label}: {e}"));
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).expect("layouts of a parsed module");
        let mut groups = declared_groups(label);
        if tlas || count {
            groups[0] = vec![crate::gpu_scene::group(tlas, count)];
        }
        let mut bound = BTreeSet::new();
        for (_, var) in module.global_variables.iter() {
            let (Some(b), Some(name)) = (&var.binding, &var.name) else { continue };
            bound.insert((b.group, b.binding, name.clone()));
            let kind = wgsl_kind(&module, &layouter, var);
            let declared = groups.get(b.group as usize).into_iter().flatten().flat_map(|g| &g.slots);
            let same = declared.filter(|s| s.binding == b.binding && s.name == name).collect::<Vec<_>>();
            if same.is_empty() {
                failures.push(format!("{label}: @group({}) @binding({}) {name} is not declared", b.group, b.binding));
            } else if same.iter().any(|s| Some(s.kind) != kind) {
                failures.push(format!("{label}: {name} is {kind:?} in WGSL, declared {:?}", same[0].kind));
            }
        }
        for (g, alternatives) in groups.iter().enumerate() {
            for group in alternatives {
                for s in &group.slots {
                    if !bound.contains(&(g as u32, s.binding, s.name.to_string())) {
                        failures.push(format!(
                            "{label}: {}'s slot {} (binding {}) is not @group({g}) @binding({}) in WGSL",
                            group.label, s.name, s.binding, s.binding
                        ));
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "declared bind groups and WGSL differ:\n{}", failures.join("\n"));
}
