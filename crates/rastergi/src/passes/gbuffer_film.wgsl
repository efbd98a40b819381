// Bind group 2 of the per-pixel passes over the G-buffer that add to the film
// (gbuffer::gbuffer_film_layout): the visible points and the film's sums.
@group(2) @binding(0) var gbuffer: texture_2d<u32>;
@group(2) @binding(1) var<storage, read_write> film: array<vec4f>;
