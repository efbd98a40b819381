//! Hostile and broken files through the command line (issue 59): each ends in one line naming
//! the problem and exit status 1 — no panic (101), no abort (134), no stack overflow — within
//! 5 s, and no case makes the process hold 1 GiB (the children's peak resident memory,
//! `getrusage`). The files are made here, as a careless exporter or an attacker would write
//! them: a Mitsuba file nested 200 000 deep, a constant emitter of radiance 3·10³⁸, an EXR
//! whose header declares 999 999 × 999 999 pixels (for `compare`, `--env` and an `envmap`),
//! `<default>`s that each repeat the previous 16 times, a DTD entity of 1 MB referenced 20 000
//! times, a `.serialized` mesh declaring 300 M triangles, textures beyond the texel budget, a
//! principled BSDF of eta −1, PLY and OBJ meshes beyond the triangle budget, and an output
//! path no file can be written to.

use std::io::Write;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

fn rastergi() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rastergi"))
}

/// Runs `rastergi ARGS` in `dir`: the exit status, stderr's lines and the time taken.
fn run(dir: &Path, args: &[&str]) -> (Option<i32>, Vec<String>, Duration) {
    let start = Instant::now();
    let out = rastergi().args(args).current_dir(dir).env("RUST_LOG", "error").output().unwrap();
    let lines = String::from_utf8_lossy(&out.stderr).lines().map(str::to_owned).collect();
    (out.status.code(), lines, start.elapsed())
}

/// A render of `scene` (in `dir`) at 16² for one iteration, with `extra` options.
fn render(dir: &Path, scene: &str, extra: &[&str]) -> (Option<i32>, Vec<String>, Duration) {
    let mut args = vec!["render", scene, "--width", "16", "--height", "16", "--iterations", "1", "--out", "o.png"];
    args.extend_from_slice(extra);
    run(dir, &args)
}

/// Checks one refused case: status 1, one line, the words that name the problem, 5 s.
fn refused(case: &str, (status, lines, took): (Option<i32>, Vec<String>, Duration), words: &[&str]) {
    println!("{case}: {:.2} s: {}", took.as_secs_f64(), lines.join(" / "));
    assert_eq!(status, Some(1), "{case}: exit status {status:?}: {lines:?}");
    assert_eq!(lines.len(), 1, "{case}: not one line: {lines:?}");
    for w in words {
        assert!(lines[0].contains(w), "{case}: '{}' does not say '{w}'", lines[0]);
    }
    assert!(took < Duration::from_secs(5), "{case}: {took:?}");
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) {
    std::fs::write(dir.join(name), bytes).unwrap();
}

const HEAD: &str = "<scene version=\"3.0.0\">\n";
const QUAD: &str = "<shape type=\"rectangle\"/>\n";

/// An EXR file of 330 bytes whose header declares `side` × `side` pixels (three half-float
/// channels, no compression) and holds no pixels.
fn exr_header(side: i32) -> Vec<u8> {
    let attr = |name: &str, ty: &str, data: &[u8]| {
        let mut a = format!("{name}\0{ty}\0").into_bytes();
        a.extend((data.len() as i32).to_le_bytes());
        a.extend(data);
        a
    };
    let mut channels = Vec::new();
    for c in ["B", "G", "R"] {
        channels.extend(format!("{c}\0").as_bytes());
        channels.extend(1i32.to_le_bytes()); // half
        channels.extend([0, 0, 0, 0]);
        channels.extend(1i32.to_le_bytes());
        channels.extend(1i32.to_le_bytes());
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
    let first = exr.len() as u64 + 8;
    exr.extend(first.to_le_bytes());
    exr.resize(330, 0);
    exr
}

/// A `.serialized` file whose mesh declares `triangles` triangles of 3 vertices, its zlib
/// stream long enough to hold them by the 1032:1 bound (the rest of it never read).
fn serialized_claiming(triangles: u64) -> Vec<u8> {
    let mut body = 0x1000u32.to_le_bytes().to_vec();
    body.extend(b"m\0");
    body.extend(3u64.to_le_bytes());
    body.extend(triangles.to_le_bytes());
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    z.write_all(&body).unwrap();
    let mut file = vec![0x1C, 0x04, 4, 0];
    file.extend(z.finish().unwrap());
    file.resize((triangles * 12 / 1032) as usize + 64, 0);
    file
}

/// Resident memory peaks of the children waited for so far, bytes.
fn children_peak() -> u64 {
    let mut usage = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: getrusage fills the struct it is given.
    let usage = unsafe {
        libc::getrusage(libc::RUSAGE_CHILDREN, usage.as_mut_ptr());
        usage.assume_init()
    };
    usage.ru_maxrss as u64 * 1024
}

#[test]
fn hostile_files_end_in_one_line_quickly_and_within_memory() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let n = 200_000;
    write(
        d,
        "deep.xml",
        format!("{HEAD}<shape type=\"rectangle\">{}{}</shape></scene>", "<a>".repeat(n), "</a>".repeat(n)),
    );
    refused("200 000 nested elements", render(d, "deep.xml", &[]), &["line 2", "xml-depth", "--budget xml-depth="]);

    for (name, radiance, why) in [
        ("rgb", "<rgb name=\"radiance\" value=\"3e38\"/>", "beyond 1e20"),
        ("spectrum", "<spectrum name=\"radiance\" value=\"3e38\"/>", "not finite"),
    ] {
        write(d, "radiance.xml", format!("{HEAD}{QUAD}<emitter type=\"constant\">{radiance}</emitter></scene>"));
        refused(&format!("radiance 3e38 ({name})"), render(d, "radiance.xml", &[]), &["line 3", "radiance", why]);
    }

    write(d, "huge.exr", exr_header(999_999));
    let texels = ["huge.exr", "999999x999999", "texels budget", "--budget texels="];
    refused("an EXR of 999 999² pixels: compare", run(d, &["compare", "huge.exr", "huge.exr"]), &texels);
    refused("an EXR of 999 999² pixels: --env", render(d, "cornell", &["--env", "huge.exr"]), &texels);
    write(
        d,
        "env.xml",
        format!(
            "{HEAD}{QUAD}<emitter type=\"envmap\"><string name=\"filename\" value=\"huge.exr\"/></emitter></scene>"
        ),
    );
    refused("an EXR of 999 999² pixels: envmap", render(d, "env.xml", &[]), &["env.xml: line 3", "envmap", "texels"]);

    let mut defaults = format!("{HEAD}<default name=\"v0\" value=\"xxxxxxxxxxxxxxxx\"/>\n");
    for i in 1..=8 {
        defaults += &format!("<default name=\"v{i}\" value=\"{}\"/>\n", format!("$v{}", i - 1).repeat(16));
    }
    write(d, "defaults.xml", format!("{defaults}{QUAD}</scene>"));
    refused("eight defaults of 16 times the previous", render(d, "defaults.xml", &[]), &["line 8", "expansion budget"]);

    let entity = format!(
        "<?xml version=\"1.0\"?>\n<!DOCTYPE scene [<!ENTITY big \"{}\">]>\n{HEAD}{QUAD}<comment>{}</comment></scene>",
        "x".repeat(1_000_000),
        "&big;".repeat(20_000)
    );
    write(d, "entity.xml", entity);
    refused("an entity of 1 MB referenced 20 000 times", render(d, "entity.xml", &[]), &["&big;", "expansion budget"]);

    write(d, "huge.serialized", serialized_claiming(300_000_000));
    write(
        d,
        "serialized.xml",
        format!(
            "{HEAD}<shape type=\"serialized\"><string name=\"filename\" value=\"huge.serialized\"/></shape></scene>"
        ),
    );
    refused(
        "a .serialized mesh of 300 M triangles",
        render(d, "serialized.xml", &[]),
        &["huge.serialized", "300000000 triangles (mesh 0)"],
    );

    // Textures beyond the texel budget (lowered, so that the files stay small): refused
    // before the one that exceeds it is decoded.
    let image = image::RgbImage::from_fn(512, 512, |x, y| image::Rgb([x as u8, y as u8, 7]));
    let mut shapes = String::new();
    for i in 0..8 {
        image.save(d.join(format!("t{i}.png"))).unwrap();
        shapes += &format!(
            "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"t{i}.png\"/></texture></bsdf></shape>\n"
        );
    }
    write(d, "textures.xml", format!("{HEAD}{shapes}<emitter type=\"constant\"/></scene>"));
    refused(
        "textures beyond the texel budget",
        render(d, "textures.xml", &["--budget", "texels=1M"]),
        &["t4.png", "1310720 texels", "--budget texels=1310720"],
    );

    write(
        d,
        "eta.xml",
        format!(
            "{HEAD}<shape type=\"rectangle\"><bsdf type=\"principled\"><float name=\"eta\" value=\"-1\"/></bsdf></shape><emitter type=\"constant\"/></scene>"
        ),
    );
    refused("a principled BSDF of eta -1", render(d, "eta.xml", &[]), &["line 2", "eta -1"]);

    // Meshes beyond the triangle budget (lowered): PLY and OBJ, standalone and in a scene.
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 100\nproperty list uchar uint vertex_indices\nend_header\n".to_vec();
    for v in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
        ply.extend(v.to_le_bytes());
    }
    let face: Vec<u8> = std::iter::once(3u8).chain([0u32, 1, 2].iter().flat_map(|i| i.to_le_bytes())).collect();
    ply.extend(face.repeat(100));
    write(d, "m.ply", ply);
    write(
        d,
        "ply.xml",
        format!("{HEAD}<shape type=\"ply\"><string name=\"filename\" value=\"m.ply\"/></shape></scene>"),
    );
    refused(
        "a PLY mesh beyond the triangle budget",
        render(d, "ply.xml", &["--budget", "triangles=50"]),
        &["m.ply", "100 triangles (its 100 faces)", "triangles budget of 50"],
    );
    let obj: String = "v 0 0 0\nv 1 0 0\nv 0 1 0\n".to_owned() + &"f 1 2 3\n".repeat(100);
    write(d, "m.obj", obj);
    refused(
        "an OBJ beyond the triangle budget",
        render(d, "m.obj", &["--budget", "triangles=50"]),
        &["m.obj", "100 triangles"],
    );
    write(
        d,
        "obj.xml",
        format!(
            "{HEAD}<shape type=\"obj\"><string name=\"filename\" value=\"m.obj\"/></shape><shape type=\"obj\"><string name=\"filename\" value=\"./m.obj\"/></shape></scene>"
        ),
    );
    refused(
        "an OBJ named twice beyond the triangle budget",
        render(d, "obj.xml", &["--budget", "triangles=150"]),
        &["obj.xml: line 2", "200 triangles (its 100 and the 100 read before)"],
    );

    let start = Instant::now();
    let args = ["render", "cornell", "--width", "32", "--height", "32", "--iterations", "5000", "--out", "/proc/x.png"];
    refused(
        "an output path no file can be written to",
        run(d, &args),
        &["/proc/x.png", "no file can be written", "checked before rendering"],
    );
    assert!(start.elapsed() < Duration::from_secs(2), "the unwritable output was found after {:?}", start.elapsed());

    let peak = children_peak();
    println!("peak resident memory of any case: {} MB", peak >> 20);
    assert!(peak < 1 << 30, "a case held {} MB", peak >> 20);
}
