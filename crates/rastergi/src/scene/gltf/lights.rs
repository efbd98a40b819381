//! `KHR_lights_punctual`.

use super::*;

/// A `KHR_lights_punctual` light placed by its node's world transform: at the node's origin,
/// shining along its local −Z; `color` × `intensity` read 1:1 as W/sr (point, spot) or W/m²
/// (directional).
pub(super) fn punctual_light(light: &::gltf::khr_lights_punctual::Light, world: Mat4) -> Res<Light> {
    use ::gltf::khr_lights_punctual::Kind;
    let value = Vec3::from(light.color()) * light.intensity();
    let position = world.transform_point3(Vec3::ZERO);
    let axis = world.transform_vector3(-Vec3::Z);
    if axis.is_nan() || axis.length() <= 1e-12 {
        return Err("its node's transform collapses the light's direction".into());
    }
    let direction = axis.normalize();
    Ok(match light.kind() {
        Kind::Point => Light::Point { position, intensity: value },
        Kind::Spot { inner_cone_angle, outer_cone_angle } => {
            Light::Spot { position, direction, intensity: value, inner: inner_cone_angle, outer: outer_cone_angle }
        }
        Kind::Directional => Light::Distant { direction, irradiance: value, angular_radius: 0.0 },
    })
}
