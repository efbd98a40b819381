//! BSDFs mapped onto the scene's material model ([`crate::bsdf`]: a diffuse base
//! under a dielectric specular layer, metal, glass; GGX with α = roughness²). See the module
//! docs of [`super`] for the table of what maps to what; textures are read in [`super::textures`].

use glam::Vec3;

use super::spectra::{conductor_f0, diffuse_fresnel, named_conductor, named_ior};
use super::values;
use super::xml::{Elem, Plugin};
use super::{Loader, Res};
use crate::scene::{AlphaMode, Material, TextureRef};

/// BSDFs nested deeper than this (through `ref`s too) are refused: a reference cycle.
const MAX_NESTING: usize = 32;

/// A colour property's value: constant, or a texture times a factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Constant(Vec3),
    Texture { texture: TextureRef, factor: Vec3 },
}

impl Value {
    /// The constant, or the texture's factor (its mean is not known here).
    pub fn factor(&self) -> Vec3 {
        match *self {
            Value::Constant(c) => c,
            Value::Texture { factor, .. } => factor,
        }
    }
}

/// GGX roughness for a Mitsuba α (our α = roughness²).
pub fn roughness_of_alpha(alpha: f32) -> f32 {
    alpha.max(0.0).sqrt().min(1.0)
}

/// The map ρ ↦ ρ' of the albedo our layered model needs under a dielectric coat of relative index η for the
/// diffuse lobe of Mitsuba's `plastic`/`roughplastic` of diffuse reflectance ρ:
///
/// ```text
/// Mitsuba:  f_d = ρ/π · (1 − F(μ_i))(1 − F(μ_o)) / (η² (1 − F_int·ρ))   (nonlinear; linear: F_int·1)
/// ours:     f_d = ρ'/π · (1 − F_s(μ_i))(1 − F_s(μ_o)) / (1 − F̄_s)
/// ⇒         ρ' = ρ (1 − F̄_s) / (η² (1 − F_int·ρ))
/// ```
///
/// with F_int = F_dr(1/η) the internal diffuse Fresnel reflectance ([`diffuse_fresnel`]),
/// F̄_s = f₀ + (1 − f₀)/21 our layer's mean Schlick reflectance, f₀ = ((η − 1)/(η + 1))²; the
/// remaining difference is Schlick's against the exact Fresnel term at each angle. For η 1.5
/// a linear plastic keeps ρ' = 1.006 ρ; a nonlinear one (`nonlinear=true`: the internal
/// bounces see the coloured base again) of ρ 0.5 gets 0.29.
pub fn plastic_albedo(eta: f32, nonlinear: bool) -> impl Fn(Vec3) -> Vec3 {
    let f_int = diffuse_fresnel(1.0 / eta as f64) as f32;
    let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
    let f_mean = f0 + (1.0 - f0) / 21.0;
    move |rho: Vec3| {
        let denominator = if nonlinear { Vec3::ONE - f_int * rho } else { Vec3::splat(1.0 - f_int) };
        (rho * (1.0 - f_mean) / (eta * eta * denominator.max(Vec3::splat(1e-6)))).clamp(Vec3::ZERO, Vec3::ONE)
    }
}

impl<'a> Loader<'a> {
    /// The scene material of a BSDF element (not yet emitting).
    pub(super) fn bsdf(&mut self, e: &'a Elem, depth: usize) -> Res<Material> {
        if depth > MAX_NESTING {
            return Err(self.err(e, format!("BSDFs nest deeper than {MAX_NESTING} (a reference cycle?)")));
        }
        let e = self.deref(e, "bsdf")?;
        let p = Plugin::new(e);
        let name = e.attr("id").map_or_else(|| format!("{} (line {})", e.ty(), e.pos.line), str::to_owned);
        let ty = p.ty();
        let rough = ty.starts_with("rough");
        let mut m = match ty {
            "diffuse" | "roughdiffuse" => {
                if ty == "roughdiffuse" {
                    self.warn_once(
                        "roughdiffuse",
                        format!("roughdiffuse is read as diffuse, Oren–Nayar's roughness ignored (first: '{name}')"),
                    );
                    p.get("alpha");
                }
                let albedo = self.value(&p, "reflectance", Vec3::splat(0.5))?;
                self.with_albedo(Material::diffuse(&name, Vec3::ONE), albedo, &name)
            }
            "plastic" | "roughplastic" => {
                let eta = self.ior(&p, "int_ior", 1.49)? / self.ior(&p, "ext_ior", 1.000277)?;
                let nonlinear = self.boolean(&p, "nonlinear", false)?;
                let roughness = if rough { self.alpha(&p, &name)? } else { 0.0 };
                let rho = self.value(&p, "diffuse_reflectance", Vec3::splat(0.5))?;
                let rho = self.map_value(rho, &format!("plastic{eta}{nonlinear}"), plastic_albedo(eta, nonlinear));
                let specular = self.specular_weight(&p, "specular_reflectance", &name)?;
                let base = Material { specular, ior: eta, roughness, ..Material::diffuse(&name, Vec3::ONE) };
                self.with_albedo(base, rho, &name)
            }
            "conductor" | "roughconductor" => {
                let (eta, k) = self.conductor(&p, &name)?;
                let tint = self.constant(&p, "specular_reflectance", Vec3::ONE, &name)?;
                let base = (conductor_f0(eta, k) * tint).clamp(Vec3::ZERO, Vec3::ONE);
                let roughness = if rough { self.alpha(&p, &name)? } else { 0.0 };
                Material { metallic: 1.0, roughness, specular: 1.0, ..Material::diffuse(&name, base) }
            }
            "dielectric" | "roughdielectric" | "thindielectric" => {
                let eta = self.ior(&p, "int_ior", 1.5046)? / self.ior(&p, "ext_ior", 1.000277)?;
                let reflect = self.constant(&p, "specular_reflectance", Vec3::ONE, &name)?;
                if reflect != Vec3::ONE {
                    self.warn_once("glass reflectance", format!("a dielectric's specular_reflectance is ignored: glass reflects by Fresnel's law alone (first: '{name}', {reflect})"));
                }
                let tint = self.constant(&p, "specular_transmittance", Vec3::ONE, &name)?.clamp(Vec3::ZERO, Vec3::ONE);
                let roughness = if rough { self.alpha(&p, &name)? } else { 0.0 };
                Material {
                    transmission: 1.0,
                    specular: 1.0,
                    ior: eta.max(1e-3),
                    thin: ty == "thindielectric",
                    roughness,
                    ..Material::diffuse(&name, tint)
                }
            }
            "twosided" => {
                let inner = self.inner(&p, e, &name, depth)?;
                Material { two_sided: true, ..inner }
            }
            "bumpmap" => {
                p.get("map");
                p.get("scale");
                p.nested(&["texture"]);
                self.warn_once(
                    "bumpmap",
                    format!("bump maps are not supported (materials take normal maps only); the bumpmap's BSDF is used without them (first: '{name}')"),
                );
                self.inner(&p, e, &name, depth)?
            }
            "normalmap" => {
                let map = p.get("normalmap").or_else(|| p.nested(&["texture"]).first().copied());
                let mut inner = self.inner(&p, e, &name, depth)?;
                if let Some(map) = map {
                    match self.texture_value(map, true)? {
                        Value::Texture { texture, .. } => {
                            inner.normal_texture = Some(texture);
                            inner.normal_scale = 1.0;
                        }
                        Value::Constant(_) => {
                            self.warn(format!("normalmap '{name}': its map is not a bitmap; it is ignored"))
                        }
                    }
                }
                inner
            }
            "mask" => {
                let opacity = self.value_with(&p, "opacity", Vec3::splat(0.5), true)?;
                let mut inner = self.inner(&p, e, &name, depth)?;
                inner.alpha_mode = AlphaMode::Blend;
                match opacity {
                    Value::Constant(c) => inner.opacity = (c.x + c.y + c.z) / 3.0,
                    Value::Texture { texture, factor } => {
                        inner.opacity = ((factor.x + factor.y + factor.z) / 3.0).clamp(0.0, 1.0);
                        inner.opacity_texture = Some(texture);
                    }
                }
                inner.opacity = inner.opacity.clamp(0.0, 1.0);
                inner
            }
            "blendbsdf" => {
                let weight = self.value(&p, "weight", Vec3::splat(0.5))?.factor();
                let w = (weight.x + weight.y + weight.z) / 3.0;
                let inner = self.nested_of(&p, "bsdf");
                if inner.len() != 2 {
                    return Err(self.err(e, format!("blendbsdf '{name}' needs two BSDFs, not {}", inner.len())));
                }
                let pick = usize::from(w > 0.5);
                self.warn_once(
                    "blendbsdf",
                    format!(
                        "blends are not supported: a blendbsdf is read as the BSDF of the larger weight (first: blendbsdf '{name}', its {} BSDF of weight {:.2})",
                        ["first", "second"][pick],
                        if pick == 1 { w } else { 1.0 - w }
                    ),
                );
                self.bsdf(inner[pick], depth + 1)?
            }
            "coating" | "roughcoating" => {
                let eta = self.ior(&p, "int_ior", 1.5046)? / self.ior(&p, "ext_ior", 1.000277)?;
                if (eta - 1.5).abs() > 0.05 {
                    self.warn_once(
                        "coat index",
                        format!("{ty}: the coat's index is read as 1.5, the clear coat's (first: '{name}', {eta})"),
                    );
                }
                for unused in ["thickness", "sigma_a", "specular_reflectance"] {
                    if p.get(unused).is_some() {
                        self.warn_once(
                            &format!("{ty} {unused}"),
                            format!("{ty}: {unused} is ignored (first: '{name}')"),
                        );
                    }
                }
                let roughness = if rough { self.alpha(&p, &name)? } else { 0.0 };
                let inner = self.inner(&p, e, &name, depth)?;
                Material { clearcoat: 1.0, clearcoat_roughness: roughness, ..inner }
            }
            "principled" => self.principled(&p, &name)?,
            "null" => Material { opacity: 0.0, alpha_mode: AlphaMode::Blend, ..Material::diffuse(&name, Vec3::ZERO) },
            "phong" => {
                let albedo = self.value(&p, "diffuse_reflectance", Vec3::splat(0.5))?;
                p.read_all();
                self.warn_once(
                    "phong",
                    format!("phong is read as a diffuse surface of its diffuse_reflectance, its Phong lobe not supported (first: '{name}')"),
                );
                self.with_albedo(Material::diffuse(&name, Vec3::ONE), albedo, &name)
            }
            other => {
                p.read_all();
                self.warn_once(
                    &format!("bsdf {other}"),
                    format!(
                        "the BSDF type '{other}' is not supported; it is read as diffuse grey 0.5 (first: '{name}')"
                    ),
                );
                Material::diffuse(&name, Vec3::splat(0.5))
            }
        };
        m.name = name;
        self.warn_unread(&p, &format!("bsdf '{}'", ty));
        Ok(m)
    }

    /// A `ref` element's target (which must be a `tag`), or the element itself.
    pub(super) fn deref(&self, e: &'a Elem, tag: &str) -> Res<&'a Elem> {
        if e.tag != "ref" {
            return Ok(e);
        }
        let id = e.attr("id").ok_or_else(|| self.err(e, "<ref> needs an id"))?;
        let target = *self.ids.get(id).ok_or_else(|| self.err(e, format!("no object has the id '{id}'")))?;
        if target.tag != tag {
            return Err(self.err(e, format!("'{id}' is a <{}>, where a <{tag}> belongs", target.tag)));
        }
        Ok(target)
    }

    /// The one BSDF nested in a wrapper (twosided, bumpmap, mask …).
    fn inner(&mut self, p: &Plugin<'a>, e: &'a Elem, name: &str, depth: usize) -> Res<Material> {
        let inner = self.nested_of(p, "bsdf");
        match inner.as_slice() {
            [] => Err(self.err(e, format!("{} '{name}' holds no BSDF", e.ty()))),
            [one, rest @ ..] => {
                if !rest.is_empty() {
                    self.warn_once(
                        "two BSDFs",
                        format!(
                            "{}: only its first BSDF is used, one BSDF per side is not supported (first: '{name}')",
                            e.ty()
                        ),
                    );
                }
                self.bsdf(one, depth + 1)
            }
        }
    }

    /// `m` with its albedo from `albedo` (clamped to [0, 1]).
    fn with_albedo(&mut self, mut m: Material, albedo: Value, name: &str) -> Material {
        let mut clamp = |c: Vec3| {
            if c.max_element() > 1.0 || c.min_element() < 0.0 {
                self.warn_once(
                    "clamped",
                    format!("reflectances above 1 or below 0 are clamped to [0, 1] (first: '{name}', {c})"),
                );
            }
            c.clamp(Vec3::ZERO, Vec3::ONE)
        };
        match albedo {
            Value::Constant(c) => m.albedo = clamp(c),
            Value::Texture { texture, factor } => {
                m.albedo = clamp(factor);
                m.albedo_texture = Some(texture.texture);
                m.albedo_transform = texture.transform;
            }
        }
        m
    }

    /// α (or the mean of α_u and α_v) of a rough BSDF as GGX roughness; Beckmann is read as
    /// GGX of the same α (with a warning).
    fn alpha(&mut self, p: &Plugin<'a>, name: &str) -> Res<f32> {
        let distribution = self.string(p, "distribution")?.unwrap_or("beckmann").to_owned();
        match distribution.as_str() {
            "ggx" => {}
            "beckmann" | "phong" | "as" => self.warn_once(
                &distribution,
                format!("the {distribution} microfacet distribution is read as GGX with the same α, rastergi's microfacets being GGX (first: '{name}')"),
            ),
            other => self.warn_once(&distribution, format!("the microfacet distribution '{other}' is unknown; it is read as GGX (first: '{name}')")),
        }
        if p.has("alpha_u") || p.has("alpha_v") {
            let (u, v) = (self.constant_float(p, "alpha_u", 0.1, name)?, self.constant_float(p, "alpha_v", 0.1, name)?);
            self.warn_once(
                "anisotropic",
                format!(
                    "anisotropic roughness is read as isotropic α = √(α_u α_v) (first: '{name}', α_u {u}, α_v {v})"
                ),
            );
            return Ok(roughness_of_alpha((u * v).max(0.0).sqrt()));
        }
        p.get("sample_visible");
        Ok(roughness_of_alpha(self.constant_float(p, "alpha", 0.1, name)?))
    }

    /// A float property that may be a texture elsewhere (a texture is read as `default`).
    fn constant_float(&mut self, p: &Plugin<'a>, key: &str, default: f32, name: &str) -> Res<f32> {
        Ok(self.constant(p, key, Vec3::splat(default), name)?.x)
    }

    /// A colour that must be constant here: a texture is ignored with a warning.
    pub(super) fn constant(&mut self, p: &Plugin<'a>, key: &str, default: Vec3, name: &str) -> Res<Vec3> {
        match self.value(p, key, default)? {
            Value::Constant(c) => Ok(c),
            Value::Texture { .. } => {
                self.warn_once(
                    &format!("texture {key}"),
                    format!("a texture as {key} is not supported; {default} is used (first: '{name}')"),
                );
                Ok(default)
            }
        }
    }

    /// The plastic's specular weight: the mean of its specular_reflectance.
    fn specular_weight(&mut self, p: &Plugin<'a>, key: &str, name: &str) -> Res<f32> {
        let c = self.constant(p, key, Vec3::ONE, name)?;
        if (c.x - c.y).abs() > 1e-3 || (c.y - c.z).abs() > 1e-3 {
            self.warn_once(
                &format!("coloured {key}"),
                format!("a coloured {key} is read as its mean (first: '{name}', {c})"),
            );
        }
        Ok(((c.x + c.y + c.z) / 3.0).clamp(0.0, 1.0))
    }

    /// A conductor's (η, k) relative to its outside: `eta` and `k` given, else its `material`
    /// (Cu by default in 0.x files, `none` in 2/3).
    fn conductor(&mut self, p: &Plugin<'a>, name: &str) -> Res<(Vec3, Vec3)> {
        let ext = self.ior(p, "ext_eta", 1.0)?;
        let (eta, k) = if p.has("eta") || p.has("k") {
            p.get("material");
            (self.constant(p, "eta", Vec3::ZERO, name)?, self.constant(p, "k", Vec3::ONE, name)?)
        } else {
            let default = if self.doc.legacy() { "Cu" } else { "none" };
            let material = self.string(p, "material")?.unwrap_or(default).to_owned();
            match named_conductor(&material) {
                Some(v) => v,
                None => {
                    let at = p.get("material").map_or(p.elem, |e| e);
                    return Err(self.err(at, format!("'{material}' is not one of Mitsuba's conductor materials")));
                }
            }
        };
        Ok((eta / ext, k / ext))
    }

    /// An index of refraction: a number or one of Mitsuba's names.
    pub(super) fn ior(&mut self, p: &Plugin<'a>, key: &str, default: f32) -> Res<f32> {
        let Some(e) = p.get(key) else { return Ok(default) };
        let value = if e.tag == "string" {
            let name = self.v(values::string(e))?;
            named_ior(name)
                .ok_or_else(|| self.err(e, format!("'{name}' is not one of Mitsuba's named indices of refraction")))?
        } else {
            self.v(values::float(e))?
        };
        if !(value.is_finite() && value > 0.0) {
            return Err(self.err(e, format!("{key} {value} must be a positive number")));
        }
        Ok(value)
    }

    /// Mitsuba 3's `principled`: base_color, metallic, roughness, spec_trans and eta map 1:1
    /// onto the glTF-like model; its other lobes are named once.
    fn principled(&mut self, p: &Plugin<'a>, name: &str) -> Res<Material> {
        let albedo = self.value(p, "base_color", Vec3::splat(0.5))?;
        let metallic = self.constant_float(p, "metallic", 0.0, name)?.clamp(0.0, 1.0);
        let roughness = self.constant_float(p, "roughness", 0.5, name)?.clamp(0.0, 1.0);
        let transmission = self.constant_float(p, "spec_trans", 0.0, name)?.clamp(0.0, 1.0);
        let ior = if p.has("eta") { self.constant_float(p, "eta", 1.5, name)? } else { 1.5 };
        let base =
            Material { metallic, roughness, transmission, ior, specular: 1.0, ..Material::diffuse(name, Vec3::ONE) };
        Ok(self.with_albedo(base, albedo, name))
    }
}
