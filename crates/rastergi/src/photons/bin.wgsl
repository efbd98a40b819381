// The orientation bin of a surface side with normal n: its dominant axis and sign, 0 +x, 1 -x,
// 2 +y, 3 -y, 4 +z, 5 -z (photons::map::orientation_bin). Shared by the photon tracer's
// deposits and the map's lookups.
fn orientation_bin(n: vec3f) -> u32 {
    let a = abs(n);
    var axis = 2u;
    if a.x >= a.y && a.x >= a.z {
        axis = 0u;
    } else if a.y >= a.z {
        axis = 1u;
    }
    return 2u * axis + select(0u, 1u, n[axis] < 0.0);
}
