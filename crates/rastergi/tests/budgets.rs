//! The readers' budgets (`scene/budget.rs`) against hostile files, without a GPU: each file is
//! refused with one line naming the file, the element (its line) and the budget, and before
//! the loader allocates what the file asks for — this binary counts every allocation (its
//! global allocator), so "before allocating" is measured, not assumed. Files named by several
//! spellings of their path are read once; numbers a file hands the GPU are finite and in range.

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use rastergi::scene::{
    Budgets, Files, GltfOptions, MemoryFiles, MitsubaOptions, Scene, load_gltf_in, load_mitsuba_in, load_obj_with,
};

/// The system allocator, counting the bytes held and their peak.
struct Counting;

static HELD: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the layout is passed on as given.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let held = HELD.fetch_add(layout.size(), Ordering::SeqCst) + layout.size();
            PEAK.fetch_max(held, Ordering::SeqCst);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        // SAFETY: `p` came from `alloc` with this layout.
        unsafe { System.dealloc(p, layout) };
        HELD.fetch_sub(layout.size(), Ordering::SeqCst);
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// `f`'s result and the most bytes it held at once beyond what was held before it. (The
/// suite runs a binary's tests one at a time: `.cargo/config.toml`.)
fn peak_of<R>(f: impl FnOnce() -> R) -> (R, usize) {
    let before = HELD.load(Ordering::SeqCst);
    PEAK.store(before, Ordering::SeqCst);
    let r = f();
    (r, PEAK.load(Ordering::SeqCst).saturating_sub(before))
}

const HEAD: &str = "<scene version=\"3.0.0\">\n";
const QUAD: &str = "<shape type=\"rectangle\"/>\n";
const MB: usize = 1 << 20;

fn mitsuba(files: &MemoryFiles, budgets: Budgets) -> Result<Scene, String> {
    let options = MitsubaOptions { budgets, ..Default::default() };
    load_mitsuba_in(Files::Memory(files), Path::new("scene.xml"), &options).map(|m| m.scene).map_err(|e| e.to_string())
}

fn files(entries: &[(&str, Vec<u8>)]) -> MemoryFiles {
    let mut files = MemoryFiles::new();
    entries.iter().for_each(|(name, bytes)| files.insert(name, bytes.clone()));
    files
}

/// Loads `scene.xml` of `entries` within `budgets` and checks the refusal: one line, every
/// word of `words` in it, and at most `most` bytes held at once.
fn refused(case: &str, entries: &[(&str, Vec<u8>)], budgets: Budgets, words: &[&str], most: usize) {
    let files = files(entries);
    let (result, peak) = peak_of(|| mitsuba(&files, budgets));
    let e = result.err().unwrap_or_else(|| panic!("{case}: loaded"));
    println!("{case}: {:.1} MB held at most: {e}", peak as f64 / MB as f64);
    assert!(!e.contains('\n'), "{case}: {e}");
    for w in words {
        assert!(e.contains(w), "{case}: '{e}' does not say '{w}'");
    }
    assert!(peak <= most, "{case}: {:.1} MB held, more than {:.1}", peak as f64 / MB as f64, most as f64 / MB as f64);
}

#[test]
fn xml_nested_too_deep_is_refused_at_its_element() {
    let n = 200_000;
    let deep = format!("{HEAD}<shape type=\"rectangle\">{}{}</shape></scene>", "<a>".repeat(n), "</a>".repeat(n));
    // roxmltree holds the 200 000 elements (about 250 bytes each); 256 levels are converted.
    let words = ["scene.xml: line 2", "<a> needs 257 levels", "xml-depth budget of 256", "--budget xml-depth=257"];
    refused("200 000 nested elements", &[("scene.xml", deep.into_bytes())], Budgets::default(), &words, 64 * MB);
    let nested = |depth: usize| {
        format!("{HEAD}{}{}</scene>", "<shape type=\"rectangle\">".repeat(depth), "</shape>".repeat(depth))
    };
    let budgets = Budgets { xml_depth: 4, ..Budgets::default() };
    let e = mitsuba(&files(&[("scene.xml", nested(3).into_bytes())]), budgets).err().unwrap_or_default();
    assert!(!e.contains("xml-depth"), "three shapes in the scene are 4 levels: {e}");
    refused("5 levels", &[("scene.xml", nested(4).into_bytes())], budgets, &["needs 5 levels", "budget of 4"], MB);
}

#[test]
fn parameters_expanding_beyond_the_budget_are_refused_before_they_are_made() {
    let mut s = format!("{HEAD}<default name=\"v0\" value=\"xxxxxxxxxxxxxxxx\"/>\n");
    for i in 1..=8 {
        s += &format!("<default name=\"v{i}\" value=\"{}\"/>\n", format!("$v{}", i - 1).repeat(16));
    }
    s += QUAD;
    s += "</scene>";
    // $v5 is 16 MiB, $v6 would be 256 MiB: refused on its line, having made the 17 MiB before.
    let words = ["line 8", "268435456 bytes here", "expansion budget of 67108864", "--budget expansion="];
    refused(
        "eight defaults, each 16 of the previous",
        &[("scene.xml", s.into_bytes())],
        Budgets::default(),
        &words,
        40 * MB,
    );
    // A caller's definition counts too.
    let xml = format!("{HEAD}<shape type=\"rectangle\"><string name=\"x\" value=\"$a$a$a\"/></shape></scene>");
    let options = MitsubaOptions {
        defines: vec![("a".into(), "y".repeat(400))],
        budgets: Budgets { expansion: 1000, ..Budgets::default() },
    };
    let e =
        load_mitsuba_in(Files::Memory(&files(&[("scene.xml", xml.into_bytes())])), Path::new("scene.xml"), &options);
    assert!(e.err().unwrap().to_string().contains("needs 1200 bytes of expanded text"));
}

#[test]
fn dtd_entities_expanding_beyond_the_budget_are_refused_before_parsing() {
    let entity = format!(
        "<?xml version=\"1.0\"?>\n<!DOCTYPE scene [<!ENTITY big \"{}\">]>\n{HEAD}{QUAD}<comment>{}</comment></scene>",
        "x".repeat(1_000_000),
        "&big;".repeat(20_000)
    );
    let words = ["line 5", "20000000000 bytes", "&big;", "expansion budget"];
    refused(
        "1 MB entity referenced 20 000 times",
        &[("scene.xml", entity.into_bytes())],
        Budgets::default(),
        &words,
        8 * MB,
    );
    // Nested entities multiply: 10 levels of 10 references to a 10-byte value.
    let mut dtd = String::from("<!ENTITY e0 \"0123456789\">");
    for i in 1..=9 {
        dtd += &format!("<!ENTITY e{i} \"{}\">", format!("&e{};", i - 1).repeat(10));
    }
    let laughs =
        format!("<?xml version=\"1.0\"?>\n<!DOCTYPE scene [{dtd}]>\n{HEAD}{QUAD}<comment>&e9;</comment></scene>");
    let words = ["needs 10000000000 bytes", "&e9;"];
    refused("a billion laughs", &[("scene.xml", laughs.into_bytes())], Budgets::default(), &words, MB);
    // Within the budget, entities are read as before.
    let small = format!(
        "<?xml version=\"1.0\"?>\n<!DOCTYPE scene [<!ENTITY g \"0.25\">]>\n{HEAD}<shape type=\"rectangle\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"&g;\"/></bsdf></shape></scene>"
    );
    let scene = mitsuba(&files(&[("scene.xml", small.into_bytes())]), Budgets::default()).unwrap();
    assert_eq!(scene.materials[0].albedo, glam::Vec3::splat(0.25));
}

#[test]
fn files_beyond_the_xml_budget_are_refused_before_they_are_read() {
    // Nodes: one per 32 bytes of the budget (65 536 at least), checked as they are parsed.
    let many = format!("{HEAD}{QUAD}{}</scene>", "<a/>".repeat(70_000));
    let budgets = Budgets { xml_bytes: 1 << 20, ..Budgets::default() };
    let words =
        ["scene.xml: has more than 65536 XML nodes", "xml-bytes budget of 1048576", "--budget xml-bytes=4194304"];
    refused("70 000 elements for 65 536 nodes", &[("scene.xml", many.clone().into_bytes())], budgets, &words, 32 * MB);
    assert!(mitsuba(&files(&[("scene.xml", many.into_bytes())]), Budgets { xml_bytes: 3 << 20, ..budgets }).is_ok());
    let include = |name: &str| format!("<include filename=\"{name}\"/>");
    let part = format!("{HEAD}{QUAD}{}</scene>", " ".repeat(4000));
    let main = format!("{HEAD}{}{}</scene>", include("a.xml"), include("b.xml"));
    let entries =
        [("scene.xml", main.into_bytes()), ("a.xml", part.clone().into_bytes()), ("b.xml", part.into_bytes())];
    let budgets = Budgets { xml_bytes: 6000, ..Budgets::default() };
    refused("two includes over 6000 bytes", &entries, budgets, &["b.xml", "xml-bytes budget of 6000"], MB);
    assert!(mitsuba(&files(&entries), Budgets { xml_bytes: 9000, ..Budgets::default() }).is_ok());
}

/// A `.serialized` file whose one mesh declares `vertices` and `triangles`, its zlib stream
/// long enough for them by the 1032:1 bound (all but its start never read).
fn serialized_claiming(vertices: u64, triangles: u64) -> Vec<u8> {
    use std::io::Write;
    let mut body = 0x1000u32.to_le_bytes().to_vec();
    body.extend(b"m\0");
    body.extend(vertices.to_le_bytes());
    body.extend(triangles.to_le_bytes());
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    z.write_all(&body).unwrap();
    let mut file = vec![0x1C, 0x04, 4, 0];
    file.extend(z.finish().unwrap());
    file.resize(((vertices * 12 + triangles * 12) / 1032) as usize + 64, 0);
    file
}

#[test]
fn meshes_beyond_the_triangle_vertex_and_decompression_budgets_are_refused_before_reading() {
    let shape = |file: &str| {
        format!("{HEAD}<shape type=\"serialized\"><string name=\"filename\" value=\"{file}\"/></shape></scene>")
    };
    let entries = |file: Vec<u8>| vec![("scene.xml", shape("m.serialized").into_bytes()), ("m.serialized", file)];
    let words = [
        "line 2",
        "m.serialized needs 300000000 triangles (mesh 0)",
        "triangles budget of 33554432",
        "--budget triangles=",
    ];
    refused("300 M triangles", &entries(serialized_claiming(3, 300_000_000)), Budgets::default(), &words, 8 * MB);
    let words = ["needs 100000000 vertices (mesh 0)", "vertices budget"];
    refused("100 M vertices", &entries(serialized_claiming(100_000_000, 1)), Budgets::default(), &words, 8 * MB);
    let budgets = Budgets { decompressed: 1 << 20, ..Budgets::default() };
    let words = ["needs 1200036 bytes decompressed (mesh 0)", "decompressed budget of 1048576"];
    refused("1.2 MB to decompress", &entries(serialized_claiming(3, 100_000)), budgets, &words, 2 * MB);
    // OBJ and PLY: counted before they are parsed.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\nf 1 2 3\n".repeat(10);
    let budgets = Budgets { triangles: 29, ..Budgets::default() };
    let mut m = MemoryFiles::new();
    m.insert("m.obj", obj.clone().into_bytes());
    let e = load_obj_with(Files::Memory(&m), Path::new("m.obj"), &budgets).unwrap_err().to_string();
    assert!(e.starts_with("m.obj: needs 30 triangles (its f lines)"), "{e}");
    let e = load_obj_with(Files::Memory(&m), Path::new("m.obj"), &Budgets { vertices: 39, ..budgets }).unwrap_err();
    assert!(e.to_string().starts_with("m.obj: needs 40 vertices (its v lines)"), "{e}");
    // One mesh named by three shapes (two spellings): read once, counted three times.
    let three = format!(
        "{HEAD}{}</scene>",
        ["m.obj", "./m.obj", "x/../m.obj"]
            .map(|f| format!("<shape type=\"obj\"><string name=\"filename\" value=\"{f}\"/></shape>"))
            .concat()
    );
    let entries = [("scene.xml", three.into_bytes()), ("m.obj", obj.into_bytes())];
    let scene = mitsuba(&files(&entries), Budgets { triangles: 90, ..Budgets::default() }).unwrap();
    assert_eq!(scene.triangles.len(), 90);
    let words = ["line 2", "the shape needs 90 triangles (its 30 and the 60 read before)", "budget of 89"];
    refused("a mesh named three times", &entries, Budgets { triangles: 89, ..Budgets::default() }, &words, MB);
}

/// A PNG of `w` × `h` grey texels.
fn png(w: u32, h: u32) -> Vec<u8> {
    let mut bytes = Vec::new();
    let image = image::GrayImage::from_pixel(w, h, image::Luma([128]));
    image.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).unwrap();
    bytes
}

#[test]
fn textures_are_read_once_per_file_and_refused_beyond_the_texel_budget_before_decoding() {
    let bitmap = |file: &str| {
        format!(
            "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"{file}\"/></texture></bsdf></shape>\n"
        )
    };
    // One 2048² image by sixteen spellings of its path: one texture, decoded once.
    let spellings: Vec<String> = (0..16).map(|i| format!("{}big.png", "a/../".repeat(i))).collect();
    let xml = format!("{HEAD}{}</scene>", spellings.iter().map(|s| bitmap(s)).collect::<String>());
    let entries = [("scene.xml", xml.into_bytes()), ("big.png", png(2048, 2048))];
    let budgets = Budgets { texels: 2048 * 2048, ..Budgets::default() };
    let (scene, peak) = peak_of(|| mitsuba(&files(&entries), budgets));
    let scene = scene.unwrap();
    println!(
        "sixteen spellings of one 2048² image: {} texture, {:.1} MB held at most",
        scene.textures.len(),
        peak as f64 / MB as f64
    );
    assert_eq!(scene.textures.len(), 1);
    // Its 16 MiB of texels, and the decoder's buffer: not sixteen of them.
    assert!(peak < 40 * MB, "{peak}");
    // Distinct images: refused at the one beyond the budget, before it is decoded.
    let xml = format!("{HEAD}{}</scene>", (0..16).map(|i| bitmap(&format!("t{i}.png"))).collect::<String>());
    let mut entries = vec![("scene.xml", xml.into_bytes())];
    let names: Vec<String> = (0..16).map(|i| format!("t{i}.png")).collect();
    names.iter().for_each(|n| entries.push((n.as_str(), png(1024, 1024))));
    let words =
        ["line 6", "t4.png needs 5242880 texels (1024x1024 and the 4194304 read before)", "--budget texels=5242880"];
    refused("sixteen 1024² images", &entries, Budgets { texels: 4 << 20, ..Budgets::default() }, &words, 32 * MB);
}

#[test]
fn gltf_images_naming_one_file_are_one_texture_within_the_texel_budget() {
    let gltf = |images: &[&str]| {
        let images: Vec<String> = images.iter().map(|u| format!("{{\"uri\":\"{u}\"}}")).collect();
        let textures: Vec<String> = (0..images.len()).map(|i| format!("{{\"source\":{i}}}")).collect();
        let materials: Vec<String> = (0..images.len())
            .map(|i| format!("{{\"pbrMetallicRoughness\":{{\"baseColorTexture\":{{\"index\":{i}}}}}}}"))
            .collect();
        // One triangle per material, all in one buffer: positions, then texture coordinates.
        let mut bin: Vec<u8> = Vec::new();
        [0f32, 0., 0., 1., 0., 0., 0., 1., 0.].iter().for_each(|v| bin.extend(v.to_le_bytes()));
        [0f32, 0., 1., 0., 0., 1.].iter().for_each(|v| bin.extend(v.to_le_bytes()));
        use base64::Engine as _;
        let data = base64::engine::general_purpose::STANDARD.encode(&bin);
        let primitives: Vec<String> = (0..images.len())
            .map(|i| format!("{{\"attributes\":{{\"POSITION\":0,\"TEXCOORD_0\":1}},\"material\":{i}}}"))
            .collect();
        format!(
            "{{\"asset\":{{\"version\":\"2.0\"}},\"scene\":0,\"scenes\":[{{\"nodes\":[0]}}],\"nodes\":[{{\"mesh\":0}}],\
             \"meshes\":[{{\"primitives\":[{}]}}],\"materials\":[{}],\"textures\":[{}],\"images\":[{}],\
             \"buffers\":[{{\"byteLength\":60,\"uri\":\"data:application/octet-stream;base64,{data}\"}}],\
             \"bufferViews\":[{{\"buffer\":0,\"byteLength\":36}},{{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24}}],\
             \"accessors\":[{{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]}},\
             {{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}}]}}",
            primitives.join(","),
            materials.join(","),
            textures.join(","),
            images.join(",")
        )
    };
    let mut m = MemoryFiles::new();
    m.insert("t.png", png(64, 64));
    m.insert("u.png", png(64, 64));
    m.insert("scene.gltf", gltf(&["t.png", "./t.png", "x/../t.png"]).into_bytes());
    let load = |m: &MemoryFiles, texels: u64| {
        let options = GltfOptions { budgets: Budgets { texels, ..Budgets::default() }, ..Default::default() };
        load_gltf_in(Files::Memory(m), Path::new("scene.gltf"), &options).map_err(|e| e.to_string())
    };
    let scene = load(&m, 64 * 64).unwrap();
    assert_eq!((scene.textures.len(), scene.triangles.len()), (1, 3));
    m.insert("scene.gltf", gltf(&["t.png", "u.png"]).into_bytes());
    let e = load(&m, 64 * 64).unwrap_err();
    assert!(
        e.contains("image 1 needs 8192 texels (64x64 and the 4096 read before)") && e.contains("--budget texels=8192"),
        "{e}"
    );
}

#[test]
fn numbers_a_file_hands_the_gpu_are_finite_and_in_range() {
    let load = |body: &str| {
        mitsuba(&files(&[("scene.xml", format!("{HEAD}{body}</scene>").into_bytes())]), Budgets::default())
    };
    for (case, body, words) in [
        (
            "a constant emitter of 3e38",
            "<emitter type=\"constant\"><rgb name=\"radiance\" value=\"3e38\"/></emitter>",
            "radiance",
        ),
        (
            "an equal-energy spectrum of 3e38 (inf in RGB)",
            "<emitter type=\"constant\"><spectrum name=\"radiance\" value=\"3e38\"/></emitter>",
            "inf",
        ),
        (
            "a point light of 1e21 W/sr",
            "<emitter type=\"point\"><rgb name=\"intensity\" value=\"1e21\"/></emitter>",
            "intensity",
        ),
        (
            "a negative irradiance",
            "<emitter type=\"directional\"><rgb name=\"irradiance\" value=\"-1\"/></emitter>",
            "irradiance",
        ),
        (
            "an area emitter of 1e30",
            "<shape type=\"rectangle\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"1e30\"/></emitter></shape>",
            "area emitter's radiance",
        ),
        (
            "a principled eta of -1",
            "<shape type=\"rectangle\"><bsdf type=\"principled\"><float name=\"eta\" value=\"-1\"/></bsdf></shape>",
            "eta -1",
        ),
        (
            "a principled eta of 0",
            "<shape type=\"rectangle\"><bsdf type=\"principled\"><float name=\"eta\" value=\"0\"/></bsdf></shape>",
            "eta 0",
        ),
        (
            "a scene 6e38 across",
            "<shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"3e38\"/></transform></shape>",
            "extent",
        ),
    ] {
        let e = load(&format!("{QUAD}{body}")).err().unwrap_or_else(|| panic!("{case}: loaded"));
        println!("{case}: {e}");
        assert!(e.contains(words) && e.starts_with("scene.xml: "), "{case}: {e}");
    }
    // Within range: the sun's radiance and a glass of η 1.5 load.
    let scene =
        load(&format!("{QUAD}<emitter type=\"constant\"><rgb name=\"radiance\" value=\"2e7\"/></emitter>")).unwrap();
    assert!(scene.environment.is_some());
}

#[test]
fn environment_maps_are_refused_by_their_header_before_their_pixels_are_read() {
    let side = 999_999i32;
    let attr = |name: &str, ty: &str, data: &[u8]| {
        let mut a = format!("{name}\0{ty}\0").into_bytes();
        a.extend((data.len() as i32).to_le_bytes());
        a.extend(data);
        a
    };
    let mut channels = Vec::new();
    for c in ["B", "G", "R"] {
        channels.extend(format!("{c}\0").as_bytes());
        [1i32].iter().for_each(|v| channels.extend(v.to_le_bytes()));
        channels.extend([0, 0, 0, 0]);
        [1i32, 1].iter().for_each(|v| channels.extend(v.to_le_bytes()));
    }
    channels.push(0);
    let window: Vec<u8> = [0, 0, side - 1, side - 1].iter().flat_map(|v: &i32| v.to_le_bytes()).collect();
    let mut exr = 20000630i32.to_le_bytes().to_vec();
    exr.extend(2i32.to_le_bytes());
    for a in [
        attr("channels", "chlist", &channels),
        attr("compression", "compression", &[0]),
        attr("dataWindow", "box2i", &window),
        attr("displayWindow", "box2i", &window),
        attr("lineOrder", "lineOrder", &[0]),
        attr("pixelAspectRatio", "float", &1f32.to_le_bytes()),
        attr("screenWindowCenter", "v2f", &[0; 8]),
        attr("screenWindowWidth", "float", &1f32.to_le_bytes()),
    ] {
        exr.extend(a);
    }
    exr.push(0);
    exr.resize(330, 0);
    let (e, peak) = peak_of(|| rastergi::environment::Environment::decode("exr", &exr, 1.0, 1 << 27).unwrap_err());
    println!("a 330-byte EXR of 999 999² pixels: {:.1} MB held at most: {e}", peak as f64 / MB as f64);
    assert!(e.contains("999999x999999") && e.contains("--budget texels=999998000001"), "{e}");
    assert!(peak < MB, "{peak}");
    // Radiance HDR likewise: its size line alone.
    let hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 999999 +X 999999\n".to_vec();
    let e = rastergi::environment::Environment::decode("hdr", &hdr, 1.0, 1 << 27).unwrap_err();
    assert!(e.contains("999999x999999") && e.contains("texels budget"), "{e}");
}
