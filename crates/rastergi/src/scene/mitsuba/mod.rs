//! Mitsuba scene files (`.xml`, format versions 0.5/0.6 and 2/3), read as published.
//!
//! **The file** ([`xml`]): parsed by `roxmltree`; `<default>` parameters, `$name` references
//! and the caller's definitions ([`MitsubaOptions::defines`], the CLI's `-D name=value`);
//! `<include>`; every element with an `id`, at any depth, can be named by `<ref id>` (Mitsuba's
//! rule: a BSDF nested in another is found by its own id). 0.x's camelCase property names are
//! read as 2/3's snake_case. A malformed file is one error line naming the file, line and
//! column; whatever is read and not used is named once in a `log::warn!`, never refused.
//!
//! **Shapes** ([`shapes`]): `obj` (through the OBJ loader's geometry, its MTL ignored; v
//! flipped as Mitsuba's `flip_tex_coords` does by default), `ply` ([`ply`]), `serialized`
//! ([`serialized`], `shape_index`), `rectangle`, `cube`, `disk`, `cylinder`, `sphere`
//! (tessellated to the exact area), `shapegroup`/`instance`; `to_world`, `flip_normals`,
//! `face_normals`.
//!
//! **BSDFs** ([`materials`]; our model in [`crate::bsdf`], GGX α = roughness², so roughness =
//! √α):
//!
//! | Mitsuba | rastergi |
//! |---|---|
//! | `diffuse` (reflectance) | Lambertian albedo (RGB or bitmap) |
//! | `plastic`, `roughplastic` | a dielectric layer of η = int_ior/ext_ior (weight: mean specular_reflectance) over a diffuse base of albedo [`materials::plastic_albedo`]`(ρ)`, which reflects what Mitsuba's diffuse lobe does under uniform light (Mitsuba's own rough-interface terms; linear or `nonlinear`), up to Schlick's Fresnel against the exact one; roughness √α |
//! | `conductor`, `roughconductor` | metal of base colour F₀(η, k) × specular_reflectance (η, k given or from `material`, [`spectra`]); roughness √α |
//! | `dielectric`, `roughdielectric`, `thindielectric` | glass: transmission 1, ior int_ior/ext_ior, tint specular_transmittance, `thin` for thindielectric; roughness √α |
//! | `twosided` | its BSDF, reflecting on both faces |
//! | `mask` | its BSDF with stochastic opacity (constant, or a bitmap's luminance) |
//! | `normalmap` | its BSDF with the (raw) bitmap as tangent-space normal map, in glTF's frame (MikkTSpace, bitangent up the image); Mitsuba's frame (∂p/∂u, n × ∂p/∂u, n) is the same where the uv mapping is not mirrored (OBJ meshes), its green axis the opposite on its own `rectangle` |
//! | `bumpmap` | its BSDF; the bumps are ignored (warned) |
//! | `blendbsdf` | the BSDF of the larger weight (warned) |
//! | `coating`, `roughcoating` | its BSDF under the clear coat (η 1.5) of roughness √α |
//! | `principled` | base_color, metallic, roughness, spec_trans, eta 1:1 |
//! | `phong`, `roughdiffuse` | diffuse of their diffuse reflectance (warned) |
//! | `null` | an invisible surface (opacity 0) |
//!
//! The Beckmann (and Phong, Ashikhmin–Shirley) microfacet distribution is read as GGX of the
//! same α, with a warning. Textures: `bitmap` (sRGB unless `raw` or 0.x's `gamma` 1; 0.x's
//! uscale/vscale/uoffset/voffset or 3's `to_uv`), `checkerboard` (generated), `scale`.
//! Spectra: one value, RGB, sRGB, wavelength:value pairs and blackbody ([`spectra`]).
//!
//! **Emitters**: `area` (radiance → the shape's emission, from its front face; a shape that
//! emits and names no BSDF is black, otherwise the default BSDF is diffuse 0.5), `point`,
//! `spot` (cutoff_angle and beam_width as the outer and inner cone; rastergi's falloff
//! between them is glTF's smooth one, Mitsuba's is linear in angle), `directional`, `envmap`
//! (with `scale`; a `to_world` rotation is applied by resampling the image), `constant`. `sun`,
//! `sky` and `sunsky` are named and skipped (not implemented yet).
//!
//! **Sensor**: `perspective` (and `thinlens` as a pinhole, warned): `to_world` gives the eye
//! (M·0), the view direction (M·ẑ) and up (M·ŷ); `fov` along `fov_axis` (x, y, diagonal,
//! smaller, larger; or 0.x's `focal_length` in 35 mm equivalents along the diagonal) becomes
//! the vertical field of view for the film's aspect a = width/height: tan(θ_y/2) =
//! tan(θ/2)·{1/a, 1, 1/√(1 + a²)} for x, y and the diagonal. A mirrored camera (its local +x to
//! the right: Mitsuba's image mirrored) is warned about. The film's size and the sampler's
//! sample count are returned in [`MitsubaScene`].

mod emitters;
mod materials;
mod ply;
mod sensor;
mod serialized;
mod shapes;
mod spectra;
mod textures;
mod values;
mod xml;

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};

use super::{Budget, Budgets, Camera, Files, Material, Scene};
use crate::error::{Error, Result};
use materials::Value;
use shapes::Soup;
use xml::{Document, Elem, Plugin};

type Res<T> = Result<T>;

/// Choices made when loading a Mitsuba file.
#[derive(Clone, Debug, Default)]
pub struct MitsubaOptions {
    /// Parameter values (`-D name=value`), overriding the file's `<default>`s.
    pub defines: Vec<(String, String)>,
    /// What the file and the files it names may make the loader read and hold.
    pub budgets: Budgets,
}

/// A Mitsuba scene and what its file suggests for rendering it.
#[derive(Clone, Debug)]
pub struct MitsubaScene {
    pub scene: Scene,
    /// The film's width and height in pixels (Mitsuba's default 768 × 576 where the sensor
    /// names none); `None` without a sensor.
    pub film: Option<(u32, u32)>,
    /// The sampler's sample count per pixel, if the file has a sensor.
    pub sample_count: Option<u32>,
}

/// Loads a Mitsuba scene file from disk.
pub fn load_mitsuba(path: &Path, options: &MitsubaOptions) -> Result<MitsubaScene> {
    load_mitsuba_in(Files::Disk, path, options)
}

/// Loads the Mitsuba scene at `path` of `files` (its meshes, textures and includes too).
pub fn load_mitsuba_in(files: Files, path: &Path, options: &MitsubaOptions) -> Result<MitsubaScene> {
    let doc = xml::parse(files, path, &options.defines, &options.budgets)?;
    let mut ids: HashMap<String, &Elem> = HashMap::new();
    let mut duplicate = None;
    doc.root.walk(&mut |e| {
        if e.tag != "ref"
            && let Some(id) = e.attr("id")
            && ids.insert(id.to_owned(), e).is_some()
            && duplicate.is_none()
        {
            duplicate = Some((e.pos, id.to_owned()));
        }
    });
    if let Some((pos, id)) = duplicate {
        return Err(Document::error_at(&doc.files, pos, format!("the id '{id}' is given to two objects")));
    }
    let mut loader = Loader {
        files,
        doc: &doc,
        ids,
        scene: Scene::new(Camera { eye: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 }),
        textures: HashMap::new(),
        derived: HashMap::new(),
        checkers: HashMap::new(),
        materials: HashMap::new(),
        mesh_files: HashMap::new(),
        meshes: HashMap::new(),
        mesh_uses: HashMap::new(),
        budgets: options.budgets,
        texels: 0,
        decompressed: 0,
        warned: HashSet::new(),
        camera: None,
        film: None,
        sample_count: None,
    };
    loader.count_mesh_uses();
    loader.build()?;
    let Loader { mut scene, camera, film, sample_count, .. } = loader;
    if scene.triangles.is_empty() {
        return Err(Error::SceneFile { path: path.to_path_buf(), message: "has no shapes with triangles".into() });
    }
    scene.camera = camera.unwrap_or_else(|| scene.default_camera());
    scene.framing = film.map(|(width, height)| super::Framing { width, height, samples: sample_count });
    scene.validate().map_err(|e| Error::SceneFile { path: path.to_path_buf(), message: e.to_string() })?;
    Ok(MitsubaScene { scene, film, sample_count })
}

pub(super) struct Loader<'a> {
    files: Files<'a>,
    doc: &'a Document,
    ids: HashMap<String, &'a Elem>,
    scene: Scene,
    /// Textures by (canonical file, read as linear data).
    textures: HashMap<(PathBuf, bool), usize>,
    /// Textures made from others (a plastic's mapped albedo, an opacity) by (source, what).
    derived: HashMap<(usize, String), usize>,
    checkers: HashMap<String, usize>,
    /// Scene materials by (BSDF element, emission).
    materials: HashMap<(usize, [u32; 3], Option<usize>), u32>,
    /// `.serialized` files' bytes by canonical file, read once however many shapes they hold.
    mesh_files: HashMap<PathBuf, Arc<Vec<u8>>>,
    /// Mesh shapes' triangles in their local space by (canonical file, what of it: the
    /// `shape_index`, flat, flipped texture coordinates), read once however many shapes
    /// name them.
    meshes: HashMap<(PathBuf, String), Arc<Soup>>,
    /// How many shapes are yet to read each mesh file (`u32::MAX`: a shapegroup's, read once
    /// per instance): a file's meshes leave the cache when its last shape has read them.
    mesh_uses: HashMap<PathBuf, u32>,
    budgets: Budgets,
    /// Texels of the textures decoded or made so far, and bytes decompressed.
    texels: u64,
    decompressed: u64,
    warned: HashSet<String>,
    camera: Option<Camera>,
    film: Option<(u32, u32)>,
    sample_count: Option<u32>,
}

impl<'a> Loader<'a> {
    /// An error at element `e`.
    fn err(&self, e: &Elem, message: impl std::fmt::Display) -> Error {
        Document::error_at(&self.doc.files, e.pos, message)
    }

    /// A value's error at its element.
    fn v<T>(&self, r: values::VRes<T>) -> Res<T> {
        r.map_err(|values::Bad(pos, m)| Document::error_at(&self.doc.files, pos, m))
    }

    /// Logs `message` once per scene, naming the scene file.
    fn warn(&mut self, message: String) {
        self.warn_once(&message.clone(), message);
    }

    /// Logs `message` the first time `key` comes up (one warning per feature, naming the
    /// first object it concerns).
    fn warn_once(&mut self, key: &str, message: String) {
        if self.warned.insert(key.to_owned()) {
            log::warn!("{}: {message}", self.doc.files[0].display());
        }
    }

    /// Names the children of `p` that were never read, once per kind of plugin.
    fn warn_unread(&mut self, p: &Plugin, what: &str) {
        let unread = p.unread();
        if !unread.is_empty() {
            let verb = if unread.len() == 1 { "is" } else { "are" };
            self.warn(format!("{what}: {} {verb} not used", unread.join(", ")));
        }
    }

    /// The folder that paths in `e`'s file are relative to.
    fn dir_of(&self, e: &Elem) -> &'a Path {
        self.doc.files[e.pos.file].parent().unwrap_or(Path::new(""))
    }

    fn float(&self, p: &Plugin<'a>, key: &str, default: f32) -> Res<f32> {
        p.get(key).map_or(Ok(default), |e| self.v(values::float(e)))
    }

    fn integer(&self, p: &Plugin<'a>, key: &str, default: i64) -> Res<i64> {
        p.get(key).map_or(Ok(default), |e| self.v(values::integer(e)))
    }

    fn boolean(&self, p: &Plugin<'a>, key: &str, default: bool) -> Res<bool> {
        p.get(key).map_or(Ok(default), |e| self.v(values::boolean(e)))
    }

    fn string(&self, p: &Plugin<'a>, key: &str) -> Res<Option<&'a str>> {
        p.get(key).map(|e| self.v(values::string(e))).transpose()
    }

    fn point(&self, p: &Plugin<'a>, key: &str) -> Res<Option<Vec3>> {
        p.get(key).map(|e| self.v(values::vec3(e))).transpose()
    }

    fn transform(&self, p: &Plugin<'a>, key: &str) -> Res<Mat4> {
        p.get(key).map_or(Ok(Mat4::IDENTITY), |e| self.v(values::transform(e)))
    }

    /// The children of `p` that are `tag` elements or references to one.
    fn nested_of(&self, p: &Plugin<'a>, tag: &str) -> Vec<&'a Elem> {
        p.nested(&[tag, "ref"])
            .into_iter()
            .filter(|c| c.tag == tag || c.attr("id").and_then(|id| self.ids.get(id)).is_none_or(|t| t.tag == tag))
            .collect()
    }

    /// Reads the scene element's children.
    fn build(&mut self) -> Res<()> {
        let doc: &'a Document = self.doc;
        let root = &doc.root;
        for e in &root.children {
            match e.tag.as_str() {
                "shape" => self.shape(e, Mat4::IDENTITY)?,
                "emitter" => self.emitter(e)?,
                "sensor" => {
                    if self.camera.is_some() {
                        self.warn(format!("only the first sensor is used; the one at line {} is not", e.pos.line));
                    } else {
                        self.sensor(e)?;
                    }
                }
                "bsdf" | "texture" if e.attr("id").is_none() => self.warn(format!(
                    "the {} '{}' at line {} has no id, so no shape uses it",
                    e.tag,
                    e.ty(),
                    e.pos.line
                )),
                "bsdf" | "texture" => {}
                "integrator" => self.warn(format!(
                    "the integrator '{}' is not used (rastergi renders with photon mapping and a final gather)",
                    e.ty()
                )),
                other => self.warn(format!("<{other}> ('{}') is not supported; it is skipped", e.ty())),
            }
        }
        Ok(())
    }

    /// A shape (placed by `parent` × its to_world) and its material.
    fn shape(&mut self, e: &'a Elem, parent: Mat4) -> Res<()> {
        let p = Plugin::new(e);
        let ty = p.ty();
        if ty == "shapegroup" {
            p.read_all();
            return Ok(());
        }
        let to_world = parent * self.transform(&p, "to_world")?;
        if ty == "instance" {
            let groups = self.nested_of(&p, "shape");
            let group = groups.first().ok_or_else(|| self.err(e, "an instance names no shapegroup (<ref id>)"))?;
            let group = self.deref_shape(group)?;
            for child in group.children.iter().filter(|c| c.tag == "shape") {
                if child.ty() == "instance" {
                    self.warn("an instance inside a shapegroup is skipped (instances do not nest)".into());
                    continue;
                }
                self.shape(child, to_world)?;
            }
            self.warn_unread(&p, "shape 'instance'");
            return Ok(());
        }
        let flip = self.boolean(&p, "flip_normals", false)?;
        let flat = self.boolean(&p, "face_normals", false)?;
        let analytic = |soup: Soup, local: Mat4| {
            let m = to_world * local;
            let mirrored = m.determinant() < 0.0;
            soup.transformed(m, flip ^ mirrored)
        };
        let soup = match ty {
            "obj" | "ply" | "serialized" => {
                let mesh = self.mesh(&p, flat)?;
                let (used, adding) = (self.scene.triangles.len() as u64, mesh.triangles.len() as u64);
                let detail = format!("its {adding}");
                let check = self.budgets.check_more(Budget::Triangles, used, adding, &detail);
                check.map_err(|m| self.err(e, format!("the shape {m}")))?;
                Arc::unwrap_or_clone(mesh).transformed(to_world, flip)
            }
            "rectangle" => analytic(shapes::rectangle(), Mat4::IDENTITY),
            "cube" => analytic(shapes::cube(), Mat4::IDENTITY),
            "disk" => analytic(shapes::disk(), Mat4::IDENTITY),
            "sphere" => {
                let center = self.point(&p, "center")?.unwrap_or(Vec3::ZERO);
                let radius = self.float(&p, "radius", 1.0)?;
                if radius.is_nan() || radius <= 0.0 {
                    return Err(self.err(e, format!("a sphere's radius {radius} must be positive")));
                }
                let soup = shapes::sphere();
                analytic(
                    if flat { Soup { normals: None, ..soup } } else { soup },
                    Mat4::from_translation(center) * Mat4::from_scale(Vec3::splat(radius)),
                )
            }
            "cylinder" => {
                let p0 = self.point(&p, "p0")?.unwrap_or(Vec3::ZERO);
                let p1 = self.point(&p, "p1")?.unwrap_or(Vec3::Z);
                let radius = self.float(&p, "radius", 1.0)?;
                let soup = shapes::cylinder(p0, p1, radius)
                    .ok_or_else(|| self.err(e, "a cylinder needs p0 ≠ p1 and a positive radius"))?;
                analytic(if flat { Soup { normals: None, ..soup } } else { soup }, Mat4::IDENTITY)
            }
            other => {
                p.read_all();
                self.warn(format!("the shape type '{other}' is not supported; it is skipped"));
                return Ok(());
            }
        };
        let bsdf = self.nested_of(&p, "bsdf").first().copied();
        let emitter = self.nested_of(&p, "emitter").first().copied();
        let emission = match emitter {
            Some(em) => Some(self.area_emission(em)?),
            None => None,
        };
        let material = self.material_for(bsdf, emission)?;
        self.add(e, soup, material)?;
        self.warn_unread(&p, &format!("shape '{ty}'"));
        Ok(())
    }

    /// A shapegroup named by an instance's reference.
    fn deref_shape(&self, e: &'a Elem) -> Res<&'a Elem> {
        let target = self.deref(e, "shape")?;
        if target.ty() != "shapegroup" {
            return Err(self.err(e, format!("an instance must name a shapegroup, not a '{}' shape", target.ty())));
        }
        Ok(target)
    }

    /// An area emitter's radiance.
    fn area_emission(&mut self, e: &'a Elem) -> Res<Value> {
        let e = self.deref(e, "emitter")?;
        let p = Plugin::new(e);
        if p.ty() != "area" {
            p.read_all();
            self.warn(format!("a shape's emitter must be 'area', not '{}'; it is skipped", p.ty()));
            return Ok(Value::Constant(Vec3::ZERO));
        }
        let spectrum = p.get("radiance").is_some_and(|e| e.tag == "spectrum");
        let radiance = match self.value(&p, "radiance", Vec3::ONE)? {
            // An emission spectrum, as Mitsuba 3's RGB mode reads it (emitters.rs).
            Value::Constant(c) if spectrum => Value::Constant(c * emitters::EQUAL_ENERGY_SRGB),
            v => v,
        };
        if let Err(m) = super::check_light(radiance.factor(), "radiance") {
            return Err(self.err(p.get("radiance").unwrap_or(e), format!("an area emitter's {m}")));
        }
        self.warn_unread(&p, "emitter 'area'");
        Ok(radiance)
    }

    /// The scene material of a shape's BSDF (or the default) with its emission.
    fn material_for(&mut self, bsdf: Option<&'a Elem>, emission: Option<Value>) -> Res<u32> {
        let bsdf = bsdf.map(|b| self.deref(b, "bsdf")).transpose()?;
        let (le, texture) = match emission {
            Some(Value::Constant(c)) => (c, None),
            Some(Value::Texture { texture, factor }) => (factor, Some(texture)),
            None => (Vec3::ZERO, None),
        };
        let key = (
            bsdf.map_or(0, |b| b as *const Elem as usize),
            le.to_array().map(f32::to_bits),
            texture.map(|t| t.texture),
        );
        if let Some(&m) = self.materials.get(&key) {
            return Ok(m);
        }
        let mut material = match bsdf {
            Some(b) => self.bsdf(b, 0)?,
            // Mitsuba's default: diffuse 0.5, black on an emitter.
            None if emission.is_some() => Material::diffuse("emitter", Vec3::ZERO),
            None => Material::diffuse("default", Vec3::splat(0.5)),
        };
        if let Err(m) = super::check_light(le, "radiance") {
            let at = bsdf.unwrap_or(&self.doc.root);
            return Err(self.err(at, format!("an area emitter's {m}")));
        }
        material.emission = le;
        material.emission_texture = texture;
        let id = self.scene.add_material(material);
        self.materials.insert(key, id);
        Ok(id)
    }

    /// A mesh file's triangles in the shape's local space, read once per canonical file (and
    /// shape index, flat shading, texture-coordinate flip) however many shapes name it.
    fn mesh(&mut self, p: &Plugin<'a>, flat: bool) -> Res<Arc<Soup>> {
        let e = p.elem;
        let filename =
            self.string(p, "filename")?.ok_or_else(|| self.err(e, format!("a {} shape needs a filename", p.ty())))?;
        let path = xml::resolve(self.dir_of(e), filename);
        if let Some(what) = self.files.missing(&path) {
            return Err(self.err(e, format!("the mesh {}: {what}", path.display())));
        }
        let canonical = self.files.canonical(&path);
        let variant = match p.ty() {
            "obj" => format!("obj flat {flat} flip {}", self.boolean(p, "flip_tex_coords", true)?),
            "ply" => format!("ply flat {flat}"),
            _ => format!("serialized {} flat {flat}", self.integer(p, "shape_index", 0)?),
        };
        let key = (canonical, variant);
        let soup = match self.meshes.get(&key) {
            Some(soup) => soup.clone(),
            None => {
                let soup = Arc::new(self.read_mesh(p, flat, &path, &key.0)?);
                self.meshes.insert(key.clone(), soup.clone());
                soup
            }
        };
        let uses = self.mesh_uses.entry(key.0.clone()).or_insert(1);
        if *uses != u32::MAX {
            *uses = uses.saturating_sub(1);
            if *uses == 0 {
                self.meshes.retain(|k, _| k.0 != key.0);
                self.mesh_files.remove(&key.0);
            }
        }
        Ok(soup)
    }

    /// Counts the shapes that name each mesh file ([`Loader::mesh_uses`]).
    fn count_mesh_uses(&mut self) {
        let doc: &'a Document = self.doc;
        let mut uses = HashMap::new();
        let mut stack: Vec<(&Elem, bool)> = doc.root.children.iter().map(|c| (c, false)).collect();
        while let Some((e, grouped)) = stack.pop() {
            if e.tag != "shape" {
                continue;
            }
            let grouped = grouped || e.ty() == "shapegroup";
            stack.extend(e.children.iter().map(|c| (c, grouped)));
            if !matches!(e.ty(), "obj" | "ply" | "serialized") {
                continue;
            }
            let Some(name) = e.children.iter().find(|c| c.name() == "filename").and_then(|c| c.attr("value")) else {
                continue;
            };
            let path = self.files.canonical(&xml::resolve(self.dir_of(e), name));
            let n: &mut u32 = uses.entry(path).or_insert(0);
            *n = if grouped { u32::MAX } else { n.saturating_add(1) };
        }
        self.mesh_uses = uses;
    }

    /// Reads a mesh file (see [`Self::mesh`]), its counts within the budgets.
    fn read_mesh(&mut self, p: &Plugin<'a>, flat: bool, path: &Path, canonical: &Path) -> Res<Soup> {
        let e = p.elem;
        let bad = |l: &Loader, m: String| l.err(e, format!("the mesh {} {m}", path.display()));
        let (budgets, used) = (self.budgets, self.scene.triangles.len() as u64);
        match p.ty() {
            "obj" => {
                let scene = super::obj::load_obj_geometry(self.files, path, &budgets, used)?;
                let flip_uv = !self.boolean(p, "flip_tex_coords", true)?;
                let uvs = (!scene.uvs.is_empty()).then(|| {
                    scene
                        .uvs
                        .iter()
                        .map(|t| if flip_uv { t.map(|uv| Vec2::new(uv.x, 1.0 - uv.y)) } else { *t })
                        .collect()
                });
                let normals = (!flat && !scene.normals.is_empty()).then_some(scene.normals);
                let soup = Soup { triangles: scene.triangles, uvs, normals };
                Ok(if flat { soup } else { soup.with_smooth_normals() })
            }
            "ply" => {
                if self.files.is_special(path) {
                    return Err(bad(self, "is not a regular file".into()));
                }
                let bytes = self.files.read(path).map_err(|err| bad(self, format!("cannot be read ({err})")))?;
                let mesh = ply::read(&bytes, &budgets, used).map_err(|m| bad(self, m))?;
                Ok(mesh.into_soup(flat))
            }
            _ => {
                let index = self.integer(p, "shape_index", 0)?;
                let index =
                    u32::try_from(index).map_err(|_| self.err(e, format!("shape_index {index} is negative")))?;
                let bytes = match self.mesh_files.get(canonical) {
                    Some(b) => b.clone(),
                    None => {
                        if self.files.is_special(path) {
                            return Err(bad(self, "is not a regular file".into()));
                        }
                        let b = Arc::new(
                            self.files.read(path).map_err(|err| bad(self, format!("cannot be read ({err})")))?,
                        );
                        self.mesh_files.insert(canonical.to_path_buf(), b.clone());
                        b
                    }
                };
                let (mesh, decompressed) =
                    serialized::read(&bytes, index, &budgets, (used, self.decompressed)).map_err(|m| bad(self, m))?;
                self.decompressed += decompressed;
                Ok(mesh.into_soup(flat))
            }
        }
    }

    /// Adds a shape's triangles with `material` (and tangents where it has a normal map),
    /// once the scene's triangles with them are known to be within budget.
    fn add(&mut self, e: &Elem, soup: Soup, material: u32) -> Res<()> {
        let (used, adding) = (self.scene.triangles.len() as u64, soup.triangles.len() as u64);
        let check = self.budgets.check_more(Budget::Triangles, used, adding, &format!("its {adding}"));
        check.map_err(|m| self.err(e, format!("the shape {m}")))?;
        let normal_mapped = self.scene.materials[material as usize].normal_texture.is_some();
        let tangents = match (&soup.uvs, normal_mapped) {
            (Some(uvs), true) => Some(super::mikktspace(&soup.triangles, uvs, soup.normals.as_deref())),
            _ => None,
        };
        for (i, t) in soup.triangles.iter().enumerate() {
            match &soup.uvs {
                Some(uvs) => self.scene.add_textured_triangle(*t, uvs[i], material),
                None => self.scene.add_triangle(*t, material),
            }
            if let Some(n) = &soup.normals {
                self.scene.set_last_normals(n[i]);
            }
            if let Some(tangents) = &tangents {
                self.scene.set_last_tangents(tangents[i]);
            }
        }
        Ok(())
    }
}
