"""The 3D back ends: the assembly as STL (one mesh, millimetres, for a slicer or a CAD import)
and as glTF (one node per part, named by it, metres as glTF's units are), through trimesh.

Each plate piece (mechc/backends/fabrication.py) is its outline less its pin holes, extruded
by the plate thickness and stacked at its plane's height: plane k spans z = k t to (k + 1) t
(plates slide on one another). The frame's base plate lies one plate under the lowest plane,
its stop blocks on the planes of the bodies they stop; the links of rod joints on the planes
the parts list gives them (mechc/backends/fabrication.py). Every part's mesh is checked
watertight before it is written.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

from mechc.backends.fabrication import Fabrication, Piece

#: The polygon triangulation trimesh extrudes with. manifold3d's: mapbox-earcut left 2 of the
#: examples' parts open (a pin hole level with a corner of its outline: sequence_detector's
#: in:x1.slider@6, speedctl's), manifold none of 505 parts over six examples.
TRIANGULATION = "manifold"

#: Plane colours (RGBA), so planes read apart in a viewer.
COLOURS = ((228, 26, 28), (55, 126, 184), (77, 175, 74), (152, 78, 163), (255, 127, 0),
           (200, 180, 40), (166, 86, 40), (247, 129, 191), (120, 120, 120))


@dataclass
class Assembly:
    parts: list[tuple[Piece, trimesh.Trimesh]]  # world mm
    thickness: float

    @property
    def bounds(self) -> np.ndarray:
        return np.array([[min(m.bounds[0][i] for _, m in self.parts) for i in range(3)],
                         [max(m.bounds[1][i] for _, m in self.parts) for i in range(3)]])


def part_mesh(piece: Piece, thickness: float) -> trimesh.Trimesh:
    """``piece`` extruded by ``thickness`` at its plane's height; a RuntimeError if the
    result is not a closed solid (a bug, not a design fault)."""
    solid = piece.solid()
    shapes = list(getattr(solid, "geoms", [solid]))
    meshes = [trimesh.creation.extrude_polygon(g, thickness, engine=TRIANGULATION)
              for g in shapes]
    m = meshes[0] if len(meshes) == 1 else trimesh.util.concatenate(meshes)
    m.apply_translation((0.0, 0.0, piece.plane * thickness))
    if not m.is_watertight or m.volume <= 0:
        raise RuntimeError(f"{piece.id}: its extruded plate is not a closed solid")
    colour = COLOURS[piece.plane % len(COLOURS)]
    m.visual.face_colors = np.tile((*colour, 255), (len(m.faces), 1))
    return m


def assembly(fab: Fabrication, progress=None) -> Assembly:
    """Every plate piece that has a plane, as a mesh (``progress(done)`` after each)."""
    parts = []
    pieces = [p for p in fab.pieces if p.plane is not None]
    for i, p in enumerate(pieces):
        parts.append((p, part_mesh(p, fab.thickness)))
        if progress is not None:
            progress(i + 1)
    return Assembly(parts, fab.thickness)


def write_stl(asm: Assembly) -> bytes:
    """One binary STL of the whole assembly, millimetres."""
    whole = trimesh.util.concatenate([m for _, m in asm.parts])
    return whole.export(file_type="stl")


def write_gltf(asm: Assembly, binary: bool = True) -> bytes:
    """The assembly as glTF 2.0, one node per part named by it, in metres (glTF's unit):
    binary (.glb), or a single .gltf text with its buffers embedded."""
    scene = trimesh.Scene()
    for p, m in asm.parts:
        mm = m.copy()
        mm.apply_scale(0.001)
        scene.add_geometry(mm, node_name=p.id, geom_name=p.id)
    if binary:
        return scene.export(file_type="glb")
    data = trimesh.exchange.gltf.export_gltf(scene, embed_buffers=True)["model.gltf"]
    return data.encode("utf-8") if isinstance(data, str) else bytes(data)
