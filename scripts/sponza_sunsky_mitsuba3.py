#!/usr/bin/env python3
"""Sponza (../shared/scenes/sponza/scene.xml, Mitsuba 0.6 XML) under a sun and sky, written in
Mitsuba 3's names so that both renderers read the same file (docs/measurements.md, "Sponza
under a sun and sky against Mitsuba 3"):

    python3 scripts/sponza_sunsky_mitsuba3.py ../shared/scenes/sponza/scene.xml spsun.xml
    rastergi render spsun.xml --width 128 --height 72 --texture-filter bilinear --out rg.exr
    python3 scripts/mitsuba_reference.py --scene spsun.xml --width 128 --height 72 --spp 4096 --out mts.exr

The sphere light above the roof becomes `<emitter type="sunsky">`: sun direction (0.3, 0.9, 0.2),
turbidity 3, ground albedo 0.3, and `to_world` turning Mitsuba 3's +Z zenith onto the scene's
+Y. The file is upgraded as Mitsuba 3 upgrades a 0.6 file (version 3.0.0, every property and
`$parameter` name from camelCase to snake_case); `max_smooth_angle`, which neither renderer
uses, is dropped; file names become absolute (the scene's folder is read-only). The scene is
not ours to commit: write the file outside the repository."""
import os
import re
import sys

src, out = sys.argv[1], sys.argv[2]
base = os.path.dirname(os.path.abspath(src))
text = open(src, encoding="utf-8").read()
start = text.index('<shape type="sphere">')
end = text.index("</shape>", start) + len("</shape>")
sky = ('<emitter type="sunsky"><vector name="sun_direction" x="0.3" y="0.9" z="0.2"/>'
       '<float name="turbidity" value="3"/><rgb name="albedo" value="0.3"/>'
       '<transform name="to_world"><rotate x="1" angle="-90"/></transform></emitter>')
text = text[:start] + sky + text[end:]
text = re.sub(r'<scene version="[^"]*"', '<scene version="3.0.0"', text)


def snake(name):
    return re.sub(r"(?<=[a-z0-9])([A-Z])", lambda m: "_" + m.group(1).lower(), name)


text = re.sub(r'name="([A-Za-z0-9_]+)"', lambda m: f'name="{snake(m.group(1))}"', text)
text = re.sub(r"\$([A-Za-z0-9_]+)", lambda m: "$" + snake(m.group(1)), text)
text = re.sub(r'<float name="max_smooth_angle" value="[^"]*"\s*/>', "", text)
text = re.sub(r'name="filename" value="([^"/][^"]*)"', lambda m: f'name="filename" value="{base}/{m.group(1)}"', text)
with open(out, "w", encoding="utf-8") as f:
    f.write(text)
