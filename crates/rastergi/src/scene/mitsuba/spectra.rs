//! Spectra reduced to linear RGB, Mitsuba's named materials (indices of refraction, conductors'
//! η and k) and the Fresnel terms the material mapping needs.
//!
//! **Wavelength pairs** ("λ:v, λ:v, …", nm) are a piecewise-linear spectrum S(λ), zero
//! outside the given range (Mitsuba's interpolated spectrum). It is reduced through the CIE
//! 1931 colour matching functions x̄, ȳ, z̄ (Wyman, Sloan and Shirley's multi-lobe Gaussian fit,
//! JCGT 2013, within about 1 % of the tables) to XYZ = ∫ S·(x̄, ȳ, z̄) dλ over 360–830 nm, then
//! to linear sRGB by the standard (D65) matrix, and each channel is divided by that of S ≡ 1:
//! a constant spectrum c gives exactly (c, c, c) (white balance to the equal-energy white).
//! **Blackbody** radiance (Planck's law, W/(m²·sr·nm)) is reduced the same way: the result is
//! its mean spectral radiance per nanometre over the visible, coloured.
//!
//! **Conductors**: the RGB η and k of Mitsuba's named materials are those that Tungsten's
//! `ComplexIorData.hpp` lists (Benedikt Bitterli reduced Mitsuba's measured spectra, the
//! `data/ior/*.spd` files, to RGB for his Mitsuba scene converter; the Wooden Staircase's
//! metals carry exactly these numbers, e.g. Au η = 0.1431, 0.3750, 1.4425). A conductor's
//! colour at normal incidence is its Fresnel reflectance there, per channel:
//! F₀ = ((η − 1)² + k²)/((η + 1)² + k²), with η and k relative to the outside's index.

use glam::Vec3;

/// sRGB decoding of one channel in [0, 1].
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// sRGB encoding of one linear channel in [0, 1].
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// A lobe of the CIE fit: a Gaussian with different widths left and right of its centre.
fn lobe(l: f64, mu: f64, left: f64, right: f64) -> f64 {
    let s = if l < mu { left } else { right };
    (-0.5 * ((l - mu) / s).powi(2)).exp()
}

/// CIE 1931 2° colour matching functions at λ nm (Wyman, Sloan, Shirley 2013).
fn cie_xyz(l: f64) -> [f64; 3] {
    [
        1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) - 0.065 * lobe(l, 501.1, 20.4, 26.2),
        0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1),
        1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8),
    ]
}

/// Linear sRGB (D65) of XYZ.
fn xyz_to_rgb([x, y, z]: [f64; 3]) -> [f64; 3] {
    [
        3.2404542 * x - 1.5371385 * y - 0.4985314 * z,
        -0.9692660 * x + 1.8760108 * y + 0.0415560 * z,
        0.0556434 * x - 0.2040259 * y + 1.0572252 * z,
    ]
}

/// RGB of a spectrum `s` (λ in nm ↦ value), white-balanced so that S ≡ 1 gives (1, 1, 1).
fn reduce(s: impl Fn(f64) -> f64) -> Vec3 {
    let (mut xyz, mut white) = ([0.0f64; 3], [0.0f64; 3]);
    // 1 nm steps over 360–830 nm, midpoints.
    for i in 0..470 {
        let l = 360.5 + i as f64;
        let c = cie_xyz(l);
        let v = s(l);
        for k in 0..3 {
            xyz[k] += v * c[k];
            white[k] += c[k];
        }
    }
    let (rgb, w) = (xyz_to_rgb(xyz), xyz_to_rgb(white));
    Vec3::new((rgb[0] / w[0]) as f32, (rgb[1] / w[1]) as f32, (rgb[2] / w[2]) as f32)
}

/// RGB of the piecewise-linear spectrum through `pairs` (λ nm increasing, value), zero outside.
pub fn pairs_to_rgb(pairs: &[(f32, f32)]) -> Vec3 {
    if let [(_, v)] = pairs {
        return Vec3::splat(*v);
    }
    let at = |l: f64| {
        let k = pairs.partition_point(|p| (p.0 as f64) <= l);
        if k == 0 || k == pairs.len() {
            // Outside, or exactly at the last sample.
            return if k == pairs.len() && (pairs[k - 1].0 as f64 - l).abs() < 1e-9 {
                pairs[k - 1].1 as f64
            } else {
                0.0
            };
        }
        let ((l0, v0), (l1, v1)) = (pairs[k - 1], pairs[k]);
        let t = (l - l0 as f64) / (l1 - l0) as f64;
        v0 as f64 * (1.0 - t) + v1 as f64 * t
    };
    reduce(at)
}

/// RGB of a blackbody's spectral radiance at `kelvin` (W/(m²·sr·nm)), reduced as [`reduce`].
pub fn blackbody_rgb(kelvin: f32) -> Vec3 {
    const TWO_HC2: f64 = 1.191_042_972e-16; // 2hc², W·m²/sr
    const HC_K: f64 = 1.438_776_877e-2; // hc/k, m·K
    let t = kelvin as f64;
    reduce(|l_nm| {
        let l = l_nm * 1e-9;
        let b = TWO_HC2 / l.powi(5) / ((HC_K / (l * t)).exp() - 1.0); // per metre
        b * 1e-9
    })
}

/// Mitsuba's named indices of refraction (its `ior` table).
pub fn named_ior(name: &str) -> Option<f32> {
    Some(match name.trim().to_ascii_lowercase().as_str() {
        "vacuum" => 1.0,
        "helium" => 1.000036,
        "hydrogen" => 1.000132,
        "air" => 1.000277,
        "carbon dioxide" => 1.00045,
        "water" => 1.3330,
        "acetone" => 1.36,
        "ethanol" => 1.361,
        "carbon tetrachloride" => 1.461,
        "glycerol" => 1.4729,
        "benzene" => 1.501,
        "silicone oil" => 1.52045,
        "bromine" => 1.661,
        "water ice" => 1.31,
        "fused quartz" => 1.458,
        "pyrex" => 1.470,
        "acrylic glass" => 1.49,
        "polypropylene" => 1.49,
        "bk7" => 1.5046,
        "sodium chloride" => 1.544,
        "amber" => 1.55,
        "pet" => 1.5750,
        "diamond" => 2.419,
        _ => return None,
    })
}

/// RGB (η, k) of Mitsuba's named conductors (module docs); `none` is a perfect mirror
/// (η 0, k 1: F₀ = 1).
pub fn named_conductor(name: &str) -> Option<(Vec3, Vec3)> {
    let name = name.trim();
    if name == "none" {
        return Some((Vec3::ZERO, Vec3::ONE));
    }
    let name = name.strip_suffix("_palik").filter(|n| *n != "Cu").unwrap_or(name);
    CONDUCTORS.iter().find(|c| c.0 == name).map(|c| (Vec3::from(c.1), Vec3::from(c.2)))
}

/// (name, η, k); `X_palik` reads `X` where the two are the same data. The digits are the
/// source's; its few slightly negative values (AlSb's η, some k of transparent materials) are 0.
#[rustfmt::skip]
#[allow(clippy::excessive_precision)]
const CONDUCTORS: &[(&str, [f32; 3], [f32; 3])] = &[
    ("a-C", [2.9440999183, 2.2271502925, 1.9681668794], [0.8874329109, 0.7993216383, 0.8152862927]),
    ("Ag", [0.1552646489, 0.1167232965, 0.1383806959], [4.8283433224, 3.1222459278, 2.1469504455]),
    ("Al", [1.6574599595, 0.8803689579, 0.5212287346], [9.2238691996, 6.2695232477, 4.8370012281]),
    ("AlAs", [3.6051023902, 3.2329365777, 2.2175611545], [0.0006670247, 0.0, 0.0074261204]),
    ("AlSb", [0.0, 4.1427547893, 4.6697691348], [0.0, 0.0937665154, 1.3007390124]),
    ("Au", [0.1431189557, 0.3749570432, 1.4424785571], [3.9831604247, 2.3857207478, 1.6032152899]),
    ("Be", [4.1850592788, 3.1850604423, 2.7840913457], [3.8354398268, 3.0101260162, 2.8690088743]),
    ("Cr", [4.3696828663, 2.9167024892, 1.6547005413], [5.2064337956, 4.2313645277, 3.7549467933]),
    ("CsI", [2.1449030413, 1.7023164587, 1.6624194173], [0.0, 0.0, 0.0]),
    ("Cu", [0.2004376970, 0.9240334304, 1.1022119527], [3.9129485033, 2.4528477015, 2.1421879552]),
    ("Cu_palik", [0.2126840430, 0.9199880064, 1.1024078212], [3.9215626225, 2.4571489948, 2.1366534268]),
    ("Cu2O", [3.5492833755, 2.9520622449, 2.7369202137], [0.1132179294, 0.1946659670, 0.6001681264]),
    ("CuO", [3.2453822204, 2.4496293965, 2.1974114493], [0.5202739621, 0.5707372756, 0.7172250613]),
    ("d-C", [2.7112524747, 2.3185812849, 2.2288565009], [0.0, 0.0, 0.0]),
    ("Hg", [2.3989314904, 1.4400254917, 0.9095512090], [6.3276269444, 4.3719414152, 3.4217899270]),
    ("HgTe", [4.7795267752, 3.2309984581, 2.6600252401], [1.6319827058, 1.5808189339, 1.7295753852]),
    ("Ir", [3.0864098394, 2.0821938440, 1.6178866805], [5.5921510077, 4.0671757150, 3.2672611269]),
    ("K", [0.0640493070, 0.0464100621, 0.0381842017], [2.1042155920, 1.3489364357, 0.9132113889]),
    ("Li", [0.2657871942, 0.1956102432, 0.2209198538], [3.5401743407, 2.3111306542, 1.6685930000]),
    ("MgO", [2.0895885542, 1.6507224525, 1.5948759692], [0.0, 0.0, 0.0]),
    ("Mo", [4.4837010280, 3.5254578255, 2.7760769438], [4.1111307988, 3.4208716252, 3.1506031404]),
    ("Na", [0.0602665320, 0.0561412435, 0.0619909494], [3.1792906496, 2.1124800781, 1.5790940266]),
    ("Nb", [3.4201353595, 2.7901921379, 2.3955856658], [3.4413817900, 2.7376437930, 2.5799132708]),
    ("Ni", [2.3672753521, 1.6633583302, 1.4670554172], [4.4988329911, 3.0501643957, 2.3454274399]),
    ("Rh", [2.5857954933, 1.8601866068, 1.5544279524], [6.7822927110, 4.7029501026, 3.9760892461]),
    ("Se-e", [5.7242724833, 4.1653992967, 4.0816099264], [0.8713747439, 1.1052845009, 1.5647788766]),
    ("Se", [4.0592611085, 2.8426947380, 2.8207582835], [0.7543791750, 0.6385150558, 0.5215872029]),
    ("SiC", [3.1723450205, 2.5259677964, 2.4793623897], [0.0000007284, 0.0, 0.0000100150]),
    ("SnTe", [4.5251865890, 1.9811525984, 1.2816819226], [0.0, 0.0, 0.0]),
    ("Ta", [2.0625846607, 2.3930915569, 2.6280684948], [2.4080467973, 1.7413705864, 1.9470377016]),
    ("Te-e", [7.5090397678, 4.2964603080, 2.3698732430], [5.5842076830, 4.9476231084, 3.9975145063]),
    ("Te", [7.3908396088, 4.4821028985, 2.6370708478], [3.2561412892, 3.5273908133, 3.2921683116]),
    ("ThF4", [1.8307187117, 1.4422274283, 1.3876488528], [0.0, 0.0, 0.0]),
    ("TiC", [3.7004673762, 2.8374356509, 2.5823030278], [3.2656905818, 2.3515586388, 2.1727857800]),
    ("TiN", [1.6484691607, 1.1504482522, 1.3797795097], [3.3684596226, 1.9434888540, 1.1020123347]),
    ("TiO2-e", [3.1065574823, 2.5131551146, 2.5823844157], [0.0000289537, 0.0, 0.0001775555]),
    ("TiO2", [3.4566203131, 2.8017076558, 2.9051485020], [0.0001026662, 0.0, 0.0006356902]),
    ("VC", [3.6575665991, 2.7527298065, 2.5326814570], [3.0683516659, 2.1986687713, 1.9631816252]),
    ("VN", [2.8656011588, 2.1191817791, 1.9400767149], [3.0323264950, 2.0561075580, 1.6162930914]),
    ("V", [4.2775126218, 3.5131538236, 2.7611257461], [3.4911844504, 2.8893580874, 3.1116965117]),
    ("W", [4.3707029924, 3.3002972445, 2.9982666528], [3.5006778591, 2.6048652781, 2.2731930614]),
];

/// A conductor's Fresnel reflectance at normal incidence, per channel, for η and k relative
/// to the outside.
pub fn conductor_f0(eta: Vec3, k: Vec3) -> Vec3 {
    let f = |n: f32, k: f32| ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
    Vec3::new(f(eta.x, k.x), f(eta.y, k.y), f(eta.z, k.z))
}

/// The exact unpolarised Fresnel reflectance of a dielectric interface of relative index
/// `eta` (inside over outside) for light arriving at cosine `cos_i` from outside (1 where it
/// is totally reflected).
pub fn dielectric_fresnel(cos_i: f64, eta: f64) -> f64 {
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// The diffuse Fresnel reflectance F_dr(η) = ∫₀¹ 2μ F(μ, η) dμ: the share of uniform
/// (Lambertian) light from the side of index 1 that an interface of relative index η
/// reflects (η < 1: light inside a denser medium, as in `fresnelDiffuseReflectance(1/η)`).
/// Midpoint rule over 4096 steps (accurate to 1e-6 except right at total internal reflection's
/// kink, where to 1e-4).
pub fn diffuse_fresnel(eta: f64) -> f64 {
    const N: usize = 4096;
    (0..N)
        .map(|i| {
            let mu = (i as f64 + 0.5) / N as f64;
            2.0 * mu * dielectric_fresnel(mu, eta)
        })
        .sum::<f64>()
        / N as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_spectrum_is_grey() {
        let rgb = pairs_to_rgb(&[(300.0, 0.5), (900.0, 0.5)]);
        assert!((rgb - Vec3::splat(0.5)).abs().max_element() < 1e-4, "{rgb}");
        // A spectrum of red light only is red.
        let red = pairs_to_rgb(&[(600.0, 0.0), (601.0, 1.0), (700.0, 1.0), (701.0, 0.0)]);
        assert!(red.x > 3.0 * red.y.max(red.z), "{red}");
    }

    #[test]
    fn diffuse_fresnel_matches_the_known_values() {
        // Glass η 1.5: F_dr ≈ 0.0918 from outside; from inside 1 − (1 − 0.0918)/η² ≈ 0.596.
        assert!((diffuse_fresnel(1.5) - 0.0918).abs() < 5e-4, "{}", diffuse_fresnel(1.5));
        let inside = diffuse_fresnel(1.0 / 1.5);
        assert!((inside - (1.0 - (1.0 - diffuse_fresnel(1.5)) / 2.25)).abs() < 1e-3, "{inside}");
    }

    #[test]
    fn named_conductors() {
        let (eta, k) = named_conductor("Au").unwrap();
        let f0 = conductor_f0(eta, k);
        assert!(f0.x > 0.9 && f0.z < 0.5, "gold is yellow: {f0}");
        assert_eq!(conductor_f0(Vec3::ZERO, Vec3::ONE), Vec3::ONE);
        assert!(named_conductor("Cu_palik").unwrap().0 != named_conductor("Cu").unwrap().0);
        assert_eq!(named_conductor("Ag_palik"), named_conductor("Ag"));
        assert!(named_conductor("unobtainium").is_none());
    }
}
