"""Mesh files and model texts the models' tests share (a unique module name: see sim_test_helpers)."""

import struct

# a unit cube centred on its origin: 8 corners, 12 triangles facing out
CUBE_CORNERS = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
CUBE_FACES = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
CUBE_TRIANGLES = [t for a, b, c, d in CUBE_FACES for t in ((a, b, c), (a, c, d))]


def write_obj(path):
    with open(path, "w") as f:
        f.writelines(f"v {x:g} {y:g} {z:g}\n" for x, y, z in CUBE_CORNERS)
        f.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in CUBE_TRIANGLES)
    return str(path)


def write_binary_stl(path):
    with open(path, "wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", len(CUBE_TRIANGLES)))
        for t in CUBE_TRIANGLES:
            f.write(struct.pack("<12fH", 0, 0, 0, *[c for i in t for c in CUBE_CORNERS[i]], 0))
    return str(path)


def write_ascii_stl(path):
    with open(path, "w") as f:
        f.write("solid cube\n")
        for t in CUBE_TRIANGLES:
            f.write("facet normal 0 0 0\n outer loop\n")
            f.writelines("  vertex {:g} {:g} {:g}\n".format(*CUBE_CORNERS[i]) for i in t)
            f.write(" endloop\nendfacet\n")
        f.write("endsolid cube\n")
    return str(path)


def write_dae(path, meter=1.0, node="<translate>0 0 0</translate>"):
    """The cube as COLLADA: a unit of meter [m], under a node of the given transform elements."""
    positions = " ".join(f"{x:g} {y:g} {z:g}" for x, y, z in CUBE_CORNERS)
    indices = " ".join(str(i) for t in CUBE_TRIANGLES for i in t)
    with open(path, "w") as f:
        f.write(f"""<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit meter="{meter}"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries><geometry id="g"><mesh>
    <source id="p"><float_array id="pa" count="24">{positions}</float_array>
      <technique_common><accessor source="#pa" count="8" stride="3"/></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="12"><input semantic="VERTEX" source="#v" offset="0"/><p>{indices}</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s">
    <node id="n">{node}<instance_geometry url="#g"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>""")
    return str(path)


def box_sdf(name="box", size=(0.4, 0.4, 0.2), mass=2.0, *, static=False, version="1.6", extra=""):
    sx, sy, sz = size
    return f"""<?xml version="1.0"?>
<sdf version="{version}">
  <model name="{name}">
    <static>{"true" if static else "false"}</static>
    <link name="link">
      <inertial><mass>{mass}</mass>
        <inertia><ixx>{mass * (sy**2 + sz**2) / 12}</ixx><iyy>{mass * (sx**2 + sz**2) / 12}</iyy>
          <izz>{mass * (sx**2 + sy**2) / 12}</izz></inertia></inertial>
      <collision name="collision"><geometry><box><size>{sx} {sy} {sz}</size></box></geometry>{extra}</collision>
      <visual name="visual"><geometry><box><size>{sx} {sy} {sz}</size></box></geometry></visual>
    </link>
  </model>
</sdf>"""


def gate_sdf(damping=0.0, friction=0.0, version="1.6"):
    """A post fixed to the world and a 1 m door of 5 kg on a vertical hinge at the post."""
    return f"""<sdf version="{version}"><model name="gate">
  <link name="post"><pose>0 0 0.5 0 0 0</pose>
    <collision name="collision"><geometry><box><size>0.1 0.1 1</size></box></geometry></collision></link>
  <link name="door"><pose>0.6 0 0.5 0 0 0</pose>
    <inertial><mass>5</mass><inertia><ixx>0.27</ixx><iyy>0.68</iyy><izz>0.42</izz></inertia></inertial>
    <collision name="collision"><geometry><box><size>1 0.05 0.8</size></box></geometry></collision></link>
  <joint name="hinge" type="revolute"><pose>-0.5 0 0 0 0 0</pose><parent>post</parent><child>door</child>
    <axis><xyz>0 0 1</xyz>
      <dynamics><damping>{damping}</damping><friction>{friction}</friction></dynamics></axis></joint>
  <joint name="to_world" type="fixed"><parent>world</parent><child>post</child></joint>
</model></sdf>"""


def many_links_sdf(n):
    """An SDF text of n empty links, built fast (a 10^6-link file is about 24 MB)."""
    return "<sdf version='1.6'><model name='huge'>" + "<link name='l'/>" * n + "</model></sdf>"
