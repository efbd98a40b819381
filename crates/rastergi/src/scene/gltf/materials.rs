//! Materials: glTF's metallic-roughness model, its extensions (emissive strength, ior,
//! transmission, volume with its attenuation, specular, clearcoat), alpha modes, normal maps
//! and textures with their KHR_texture_transform.

use super::*;

impl Loader<'_> {
    /// The scene material of a glTF material, created on first use.
    pub(super) fn material(&mut self, m: &::gltf::Material) -> Res<u32> {
        if let Some(&id) = self.materials.get(&m.index()) {
            return Ok(id);
        }
        let material = match m.index() {
            None => Material::diffuse("default", Vec3::splat(DEFAULT_ALBEDO)),
            Some(index) => {
                let what = named("material", index, m.name());
                let coat = Clearcoat::of(m).map_err(|e| format!("{what}: {e}"))?;
                if coat.normal_texture && !std::mem::replace(&mut self.warned_coat_normal, true) {
                    log::warn!(
                        "{what}: KHR_materials_clearcoat's clearcoatNormalTexture is ignored; the coat shares the base's shading normal"
                    );
                }
                let document = self.document;
                let pbr = m.pbr_metallic_roughness();
                let mut texture = |info: Option<(::gltf::Texture, UvTransform)>, linear: bool| match info {
                    Some((t, transform)) => self
                        .texture(&t, linear)
                        .map(|texture| Some(TextureRef { texture, transform }))
                        .map_err(|e| format!("{what}: {e}")),
                    None => Ok(None),
                };
                let base = texture(pbr.base_color_texture().map(|i| (i.texture(), info_transform(&i))), false)?;
                let emission = Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
                let emissive = m.emissive_texture().filter(|_| emission.max_element() > 0.0);
                let emission_texture = texture(emissive.map(|i| (i.texture(), info_transform(&i))), false)?;
                let normal = m.normal_texture();
                let normal_scale = normal.as_ref().map_or(1.0, |n| n.scale());
                let normal_texture = texture(normal.map(|n| (n.texture(), normal_transform(&n))), true)?;
                let alpha_mode = match m.alpha_mode() {
                    ::gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                    ::gltf::material::AlphaMode::Mask => AlphaMode::Mask { cutoff: m.alpha_cutoff().unwrap_or(0.5) },
                    ::gltf::material::AlphaMode::Blend => AlphaMode::Blend,
                };
                if let AlphaMode::Mask { cutoff } = alpha_mode
                    && !(cutoff.is_finite() && cutoff >= 0.0)
                {
                    return Err(format!("{what}: alphaCutoff {cutoff} is not a non-negative number"));
                }
                let opacity = pbr.base_color_factor()[3];
                if !(0.0..=1.0).contains(&opacity) {
                    return Err(format!("{what}: baseColorFactor's alpha {opacity} is outside [0, 1]"));
                }
                let metal_rough = pbr.metallic_roughness_texture().map(|i| (i.texture(), info_transform(&i)));
                let metal_rough_texture = texture(metal_rough, true)?;
                let unit = |name: &str, v: f32| -> Res<f32> {
                    if (0.0..=1.0).contains(&v) { Ok(v) } else { Err(format!("{what}: {name} {v} is outside [0, 1]")) }
                };
                let metallic = unit("metallicFactor", pbr.metallic_factor())?;
                let roughness = unit("roughnessFactor", pbr.roughness_factor())?;
                let transmission = m.transmission();
                let transmission_info = transmission.as_ref().and_then(|t| t.transmission_texture());
                let transmission_texture = texture(transmission_info.map(|i| (i.texture(), info_transform(&i))), true)?;
                let transmission = unit("transmissionFactor", transmission.map_or(0.0, |t| t.transmission_factor()))?;
                let ior = m.ior().unwrap_or(1.5);
                if !(ior.is_finite() && (ior == 0.0 || ior >= 1.0)) {
                    return Err(format!("{what}: ior {ior} is not 0 or at least 1"));
                }
                // ior 0 is the extension's "infinite": a perfect reflector; clamped to 10⁴.
                let ior = if ior == 0.0 { 1e4 } else { ior };
                let specular = m.specular();
                let specular_info = specular.as_ref().and_then(|s| s.specular_texture());
                let specular_texture = texture(specular_info.map(|i| (i.texture(), info_transform(&i))), true)?;
                let color_info = specular.as_ref().and_then(|s| s.specular_color_texture());
                let specular_color_texture = texture(color_info.map(|i| (i.texture(), info_transform(&i))), false)?;
                let specular_color = Vec3::from(specular.as_ref().map_or([1.0; 3], |s| s.specular_color_factor()));
                if !(specular_color.is_finite() && specular_color.min_element() >= 0.0) {
                    return Err(format!("{what}: specularColorFactor {specular_color} is not a non-negative colour"));
                }
                let specular = unit("specularFactor", specular.map_or(1.0, |s| s.specular_factor()))?;
                // A volume makes the glass a refracting solid; thickness 0 (its default) or no
                // volume: thin-walled, as the extension says.
                let thin = m.volume().is_none_or(|v| v.thickness_factor() <= 0.0);
                // Beer–Lambert inside the solid: σ = −ln(attenuationColor)/attenuationDistance
                // (the extension's definition; distance +∞, its default, is clear glass). The
                // thickness itself (and its texture) is for renderers without the geometry.
                let attenuation = match m.volume() {
                    Some(v) if !thin => {
                        let (d, c) = (v.attenuation_distance(), Vec3::from(v.attenuation_color()));
                        if d.is_nan() || d <= 0.0 {
                            return Err(format!("{what}: attenuationDistance {d} is not positive"));
                        }
                        if !(c.min_element() >= 0.0 && c.max_element() <= 1.0) {
                            return Err(format!("{what}: attenuationColor {c} is outside [0, 1]"));
                        }
                        if d.is_infinite() { Vec3::ZERO } else { -c.max(Vec3::splat(1e-30)).ln() / d }
                    }
                    _ => Vec3::ZERO,
                };
                let mut coat_texture = |info: Option<::gltf::json::texture::Info>| -> Res<Option<TextureRef>> {
                    let Some(info) = info else { return Ok(None) };
                    let t = document.textures().nth(info.index.value()).ok_or_else(|| {
                        format!(
                            "{what}: a clearcoat texture names texture {}, which does not exist",
                            info.index.value()
                        )
                    })?;
                    texture(Some((t, json_info_transform(&info))), true)
                };
                let clearcoat_texture = coat_texture(coat.texture)?;
                let clearcoat_roughness_texture = coat_texture(coat.roughness_texture)?;
                let clearcoat = unit("clearcoatFactor", coat.factor)?;
                let clearcoat_roughness = unit("clearcoatRoughnessFactor", coat.roughness)?;
                Material {
                    albedo_texture: base.map(|t| t.texture),
                    albedo_transform: base.map_or(UvTransform::IDENTITY, |t| t.transform),
                    emission,
                    emission_texture,
                    opacity,
                    opacity_texture: base.filter(|_| alpha_mode != AlphaMode::Opaque),
                    alpha_mode,
                    normal_texture,
                    normal_scale,
                    metallic,
                    roughness,
                    metal_rough_texture,
                    specular,
                    specular_color,
                    specular_texture,
                    specular_color_texture,
                    ior,
                    transmission,
                    transmission_texture,
                    thin,
                    attenuation,
                    clearcoat,
                    clearcoat_roughness,
                    clearcoat_texture,
                    clearcoat_roughness_texture,
                    two_sided: m.double_sided(),
                    ..Material::diffuse(
                        &m.name().map_or_else(|| format!("material {index}"), str::to_owned),
                        Vec3::from_slice(&pbr.base_color_factor()[..3]),
                    )
                }
            }
        };
        let id = self.scene.add_material(material);
        self.materials.insert(m.index(), id);
        Ok(id)
    }

    /// The scene texture of a glTF texture's image (sRGB colour, or `linear` data), decoded on
    /// first use.
    pub(super) fn texture(&mut self, texture: &::gltf::Texture, linear: bool) -> Res<usize> {
        let sampler = texture.sampler();
        use ::gltf::texture::WrappingMode::Repeat;
        if (sampler.wrap_s() != Repeat || sampler.wrap_t() != Repeat)
            && !std::mem::replace(&mut self.warned_sampler, true)
        {
            log::warn!("textures are always sampled with repeat addressing; clamped and mirrored samplers are ignored");
        }
        let image = texture.source();
        if let Some(&t) = self.textures.get(&(image.index(), linear)) {
            return Ok(t);
        }
        let what = named("image", image.index(), image.name());
        let file = match image.source() {
            ::gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => {
                Some(self.files.canonical(&self.dir.join(percent_decode(uri))))
            }
            _ => None,
        };
        if let Some(&t) = file.as_ref().and_then(|f| self.image_files.get(&(f.clone(), linear))) {
            self.textures.insert((image.index(), linear), t);
            return Ok(t);
        }
        let bytes: Vec<u8> = match image.source() {
            ::gltf::image::Source::View { view, .. } => {
                let buffer = &self.buffers[view.buffer().index()];
                let range = view.offset().checked_add(view.length()).filter(|&end| end <= buffer.len());
                let end = range.ok_or_else(|| format!("{what}: its bufferView runs past the end of its buffer"))?;
                buffer[view.offset()..end].to_vec()
            }
            ::gltf::image::Source::Uri { uri, .. } => {
                read_uri(self.files, &self.dir, uri).map_err(|e| format!("{what}: {e}"))?
            }
        };
        let name = image.name().map_or_else(|| format!("image {}", image.index()), str::to_owned);
        let (w, h) = Texture::dimensions(&bytes).map_err(|e| format!("{what} {e}"))?;
        let n = w as u64 * h as u64;
        self.budgets
            .check_more(Budget::Texels, self.texels, n, &format!("{w}x{h}"))
            .map_err(|e| format!("{what} {e}"))?;
        self.texels += n;
        let decoded = Texture::decode(&name, &bytes).map_err(|e| format!("{what} {e}"))?;
        let t = self.scene.add_texture(if linear { decoded.into_linear() } else { decoded });
        self.textures.insert((image.index(), linear), t);
        if let Some(file) = file {
            self.image_files.insert((file, linear), t);
        }
        Ok(t)
    }
}

/// KHR_texture_transform's affine map, T(offset) · R(rotation) · S(scale): (u, v) ↦
/// (c·sx·u + s·sy·v + ox, −s·sx·u + c·sy·v + oy) with c, s the rotation's cosine and sine.
pub fn texture_transform(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> UvTransform {
    let (s, c) = rotation.sin_cos();
    UvTransform([[c * scale[0], s * scale[1], offset[0]], [-s * scale[0], c * scale[1], offset[1]]])
}

/// `KHR_materials_clearcoat`, which the `gltf` crate does not parse: its factors (0 by default),
/// clearcoatTexture (R × factor) and clearcoatRoughnessTexture (G × factor), and whether it
/// names a clearcoatNormalTexture.
#[derive(Default)]
pub(super) struct Clearcoat {
    pub factor: f32,
    pub roughness: f32,
    pub texture: Option<::gltf::json::texture::Info>,
    pub roughness_texture: Option<::gltf::json::texture::Info>,
    pub normal_texture: bool,
}

impl Clearcoat {
    pub(super) fn of(m: &::gltf::Material) -> Res<Clearcoat> {
        let Some(v) = m.extension_value("KHR_materials_clearcoat") else { return Ok(Clearcoat::default()) };
        let number = |key: &str| -> Res<f32> {
            match v.get(key) {
                None => Ok(0.0),
                Some(x) => x
                    .as_f64()
                    .map(|x| x as f32)
                    .ok_or_else(|| format!("KHR_materials_clearcoat's {key} {x} is not a number")),
            }
        };
        let info = |key: &str| -> Res<Option<::gltf::json::texture::Info>> {
            v.get(key)
                .map(|x| {
                    ::gltf::json::deserialize::from_value(x.clone())
                        .map_err(|e| format!("KHR_materials_clearcoat's {key} is not a texture reference ({e})"))
                })
                .transpose()
        };
        Ok(Clearcoat {
            factor: number("clearcoatFactor")?,
            roughness: number("clearcoatRoughnessFactor")?,
            texture: info("clearcoatTexture")?,
            roughness_texture: info("clearcoatRoughnessTexture")?,
            normal_texture: v.get("clearcoatNormalTexture").is_some(),
        })
    }

    /// The TEXCOORD sets its textures read.
    fn sets(&self) -> impl Iterator<Item = u32> + '_ {
        [&self.texture, &self.roughness_texture].into_iter().flatten().map(json_info_set)
    }
}

/// The KHR_texture_transform of a texture reference read from JSON.
fn json_info_transform(info: &::gltf::json::texture::Info) -> UvTransform {
    info.extensions
        .as_ref()
        .and_then(|e| e.texture_transform.as_ref())
        .map_or(UvTransform::IDENTITY, |t| texture_transform(t.offset.0, t.rotation.0, t.scale.0))
}

/// The TEXCOORD set of a texture reference read from JSON (its transform's texCoord first).
fn json_info_set(info: &::gltf::json::texture::Info) -> u32 {
    info.extensions
        .as_ref()
        .and_then(|e| e.texture_transform.as_ref())
        .and_then(|t| t.tex_coord)
        .unwrap_or(info.tex_coord)
}

pub(super) fn info_transform(info: &::gltf::texture::Info) -> UvTransform {
    info.texture_transform().map_or(UvTransform::IDENTITY, |t| texture_transform(t.offset(), t.rotation(), t.scale()))
}

/// The normal texture's KHR_texture_transform (the `gltf` crate leaves it unparsed there).
pub(super) fn normal_transform(n: &::gltf::material::NormalTexture) -> UvTransform {
    parsed_normal_transform(n).map_or(UvTransform::IDENTITY, |t| texture_transform(t.offset.0, t.rotation.0, t.scale.0))
}

pub(super) fn parsed_normal_transform(
    n: &::gltf::material::NormalTexture,
) -> Option<::gltf::json::extensions::texture::TextureTransform> {
    let value = n.extension_value("KHR_texture_transform")?;
    ::gltf::json::deserialize::from_value(value.clone())
        .map_err(|e| log::warn!("a normal texture's KHR_texture_transform is not valid ({e}); it is ignored"))
        .ok()
}

/// The TEXCOORD sets a material's textures read (base colour, emissive, normal map,
/// metallic-roughness, transmission, specular, specular colour, clear coat and its roughness),
/// each overridden by its KHR_texture_transform's texCoord.
pub(super) fn texture_sets(m: &::gltf::Material) -> Vec<u32> {
    let info = |i: ::gltf::texture::Info| i.texture_transform().and_then(|t| t.tex_coord()).unwrap_or(i.tex_coord());
    let base = m.pbr_metallic_roughness().base_color_texture().map(info);
    let emissive = m.emissive_texture().map(info);
    let normal =
        m.normal_texture().map(|n| parsed_normal_transform(&n).and_then(|t| t.tex_coord).unwrap_or(n.tex_coord()));
    let metal_rough = m.pbr_metallic_roughness().metallic_roughness_texture().map(info);
    let transmission = m.transmission().and_then(|t| t.transmission_texture()).map(info);
    let specular = m.specular().and_then(|s| s.specular_texture()).map(info);
    let specular_color = m.specular().and_then(|s| s.specular_color_texture()).map(info);
    let coat = Clearcoat::of(m).unwrap_or_default();
    [base, emissive, normal, metal_rough, transmission, specular, specular_color]
        .into_iter()
        .flatten()
        .chain(coat.sets())
        .collect()
}
