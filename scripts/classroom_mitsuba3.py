#!/usr/bin/env python3
"""The shared classroom (../shared/scenes/classroom/scene.xml, Mitsuba 0.6 XML) as a Mitsuba 3
XML simplified to Lambertian, which both renderers read, so that they can be compared on the
same file (docs/measurements.md, "The sun's light at the gather's hits"):

    python3 scripts/classroom_mitsuba3.py ../shared/scenes/classroom/scene.xml cls.xml 128 72

Every BSDF becomes twosided(diffuse(R)), R = `reflectance` or `diffuseReflectance` (bitmap
textures kept, bilinear: render rastergi with --texture-filter bilinear), the metals
min(`specularReflectance`, 0.8); the shapes keep their OBJ files (absolute paths), transforms
and face normals; the camera its fov and matrix, a box filter, WIDTH x HEIGHT; the `sunsky`
keeps 0.6's values in 3's names as rastergi reads 0.6's (albedo 0.15, aperture 0.5358 deg x
sunRadiusScale, the zenith turned from 3's +Z to +Y by to_world). The scene is not ours to
commit: write the file outside the repository."""
import sys, xml.etree.ElementTree as ET
src, out, w, h = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
root = ET.parse(src).getroot()
import os
base = os.path.dirname(os.path.abspath(src))
o = ['<scene version="3.0.0">', '<integrator type="path"><integer name="max_depth" value="-1"/></integrator>']
sensor = root.find('sensor')
fov = sensor.find("float[@name='fov']").get('value')
mat = sensor.find("transform/matrix").get('value')
o.append(f'<sensor type="perspective"><float name="fov" value="{fov}"/><transform name="to_world"><matrix value="{mat}"/></transform>'
         f'<sampler type="independent"><integer name="sample_count" value="64"/></sampler>'
         f'<film type="hdrfilm"><integer name="width" value="{w}"/><integer name="height" value="{h}"/><rfilter type="box"/><string name="pixel_format" value="rgb"/></film></sensor>')
def refl(b):
    for n in ('reflectance', 'diffuseReflectance'):
        e = b.find(f"*[@name='{n}']")
        if e is not None:
            if e.tag == 'texture':
                fn = e.find("string[@name='filename']").get('value')
                return f'<texture name="reflectance" type="bitmap"><string name="filename" value="{base}/{fn}"/><string name="filter_type" value="bilinear"/></texture>'
            return f'<rgb name="reflectance" value="{e.get("value")}"/>'
    e = b.find("*[@name='specularReflectance']")
    v = [min(float(x), 0.8) for x in e.get('value').split(',')]
    return f'<rgb name="reflectance" value="{v[0]}, {v[1]}, {v[2]}"/>'
for b in root.findall('bsdf'):
    inner = b.find('bsdf') if b.get('type') == 'twosided' else b
    o.append(f'<bsdf type="twosided" id="{b.get("id")}"><bsdf type="diffuse">{refl(inner)}</bsdf></bsdf>')
for s in root.findall('shape'):
    fn = s.find("string[@name='filename']").get('value')
    m = s.find("transform/matrix").get('value')
    ref = s.find('ref').get('id')
    o.append(f'<shape type="obj"><string name="filename" value="{base}/{fn}"/><boolean name="face_normals" value="true"/>'
             f'<transform name="to_world"><matrix value="{m}"/></transform><ref id="{ref}"/></shape>')
e = root.find("emitter")
g = lambda n: e.find(f"*[@name='{n}']")
d = g('sunDirection')
ap = 0.5358 * float(g('sunRadiusScale').get('value'))
o.append(f'<emitter type="sunsky"><float name="turbidity" value="{g("turbidity").get("value")}"/>'
         f'<vector name="sun_direction" x="{d.get("x")}" y="{d.get("y")}" z="{d.get("z")}"/>'
         f'<float name="sky_scale" value="{g("skyScale").get("value")}"/><float name="sun_scale" value="{g("sunScale").get("value")}"/>'
         f'<rgb name="albedo" value="0.15"/><float name="sun_aperture" value="{ap}"/>'
         f'<transform name="to_world"><rotate x="1" angle="-90"/></transform></emitter>')
for x in root:
    if x.tag not in ('bsdf', 'shape', 'emitter', 'sensor', 'integrator', 'default'):
        print('unhandled', x.tag, file=sys.stderr)
o.append('</scene>')
open(out, 'w').write('\n'.join(o))
