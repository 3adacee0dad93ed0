#!/usr/bin/env python3
"""Write the project's furnished architectural test scenes as OBJ + MTL + PNG textures.

Two closed rooms side by side, in metres, y up, deterministic (the same bytes on every run):

* room A, an office 6.0 x 2.8 x 5.0 m: four desks with monitors, keyboards (every key a small
  box), mice, pens, erasers and paper; four chairs on legs (two turned about the vertical: the
  skew faces); a meeting table turned 20 degrees; two bookshelves full of books against the
  back wall; a filing cabinet with drawer handles; a window recess closed by a dark pane; two
  ceiling lights;
* room B, a library 4.0 x 2.8 x 5.0 m: a reading table with chairs and laptops (lids leaning
  back: skew faces), four bookshelves, a tray of 1.5 cm bricks; one or two ceiling lights.

The rooms share a 0.2 m wall with a doorway (reveals on all sides), so light from either room
reaches the other. Every face is wound counter-clockwise seen from its front, and its front
looks into the air. Faces that touch (a leg on the floor, a book on a board, a key on a keyboard)
are cut where they touch, so no face lies on another or hides under one; turned footprints are
cut out of the floor by their bounding box, which is filled around them with triangles.

Variants, all from the same geometry (``--variant``):

* ``plain``: as above (also the input for ``radiosity solve --two-sided``);
* ``doubled``: every face written twice, once each way round (as SketchUp and CAD exporters do);
* ``inside-out``: room B's shell (floor, walls, ceiling) wound the wrong way round.

Style (``--style``): ``clean`` is the above; ``converted`` is the same rooms and furniture written
the way exported models come (CAD, IFC and glTF exports converted to OBJ), as ``converted-*.obj``:

* nothing is cut where it touches: furniture stands on the whole floor with its bottom faces
  kept (coincident with the floor, facing it), books lie on whole boards, shelves' backs lie on
  the wall;
* legs, plinths and cabinets are sunk 1 cm into the floor (faces that interpenetrate);
* the lights are luminaire objects, not flush panels: two closed boxes (an emitting bottom face,
  metal sides, the top face lying on the ceiling), two thin panels hung 0.3 m down with every
  face emitting (one material for the whole object, as exporters do), one single downward face
  2 cm below the ceiling;
* a partition wall in the office built as two overlapping boxes and a column through the floor
  and the ceiling (buried faces, faces inside other solids);
* every polygon written as fan triangles (exporters triangulate); the doubled copy of a face is
  triangulated along the other diagonal, so its triangles are not the first copy's.

Variants of the converted style: ``plain`` (consistently wound), ``doubled``, ``inside-out``, and
``mixed``: 30 % of the faces (seeded) wound the wrong way round, as in models stitched together
from several sources.

Materials: plain ``Kd`` colours, and textured ones (``Kd 1 1 1`` + ``map_Kd``: the PNG textures
are written by this script); lights are ``Ke`` (emitted radiance, W/sr/m^2) with ``Kd 0 0 0``.

    python3 scripts/radiance/furnished.py --out out/furnished            # all variants
    python3 scripts/radiance/furnished.py --out out/furnished --variant plain
"""

from __future__ import annotations

import argparse
import math
import random
import struct
import zlib
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import r6  # noqa: E402

VARIANTS = ("plain", "doubled", "inside-out")
CONVERTED_VARIANTS = ("plain", "doubled", "inside-out", "mixed")
# The converted style's features, each of which `--without` can leave out (to find which of
# them a difference to Radiance comes with): furniture uncut where it touches, bottoms kept and
# sunk into the floor; luminaires as boxes and hung panels (or either kind alone left flush:
# boxes, panels); the partition of overlapping boxes
# and the column through floor and ceiling; every polygon as fan triangles.
FEATURES = ("contacts", "luminaires", "boxes", "panels", "panel-tops", "solids", "triangles")
SINK = 0.01  # how far the converted style sinks furniture into the floor (m)

# Room geometry (metres).
HEIGHT = 2.8
A_X = (0.0, 6.0)
B_X = (6.2, 10.2)
Z_RANGE = (-5.0, 0.0)
DOOR_Z = (-1.6, -0.7)
DOOR_TOP = 2.1


# --------------------------------------------------------------------------------------------
# Geometry: axis-aligned rectangles that are cut where they touch, and free polygons.


@dataclass
class Rect:
    """An axis-aligned rectangle facing along +axis (sign 1) or -axis (sign -1).

    It lies in the plane x[axis] = coord and spans u in [u0, u1], v in [v0, v1], where u and v
    are the axes (axis+1) % 3 and (axis+2) % 3 (so u x v = +axis). ``holes`` are the parts cut
    away (rectangles in u, v).
    """

    axis: int
    coord: float
    sign: int
    u0: float
    u1: float
    v0: float
    v1: float
    material: str
    tag: str
    holes: list = field(default_factory=list)
    openings: list = field(default_factory=list)

    def key(self):
        return (self.axis, self.coord)


@dataclass
class Poly:
    """A finished polygon: vertices counter-clockwise around its front normal."""

    verts: list
    material: str
    tag: str


def box(x0, x1, y0, y1, z0, z1, material, tag):
    """The six outward-facing rectangles of an axis-aligned box."""
    x0, x1, y0, y1, z0, z1 = map(r6, (x0, x1, y0, y1, z0, z1))
    assert x0 < x1 and y0 < y1 and z0 < z1, (x0, x1, y0, y1, z0, z1)
    lo, hi = (x0, y0, z0), (x1, y1, z1)
    out = []
    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for sign, c in ((-1, lo[axis]), (1, hi[axis])):
            out.append(Rect(axis, c, sign, lo[u], hi[u], lo[v], hi[v], material, tag))
    return out


def shell(x0, x1, y0, y1, z0, z1, materials, tag):
    """The six inward-facing rectangles of a room; ``materials`` maps floor/ceiling/wall."""
    out = []
    for r in box(x0, x1, y0, y1, z0, z1, "", tag):
        r.sign = -r.sign
        if r.axis == 1:
            r.material = materials["floor"] if r.sign > 0 else materials["ceiling"]
        else:
            r.material = materials["wall"]
        out.append(r)
    return out


def inside(a, b):
    """Whether rectangle a (u0, u1, v0, v1) lies within rectangle b."""
    return b[0] <= a[0] and a[1] <= b[1] and b[2] <= a[2] and a[3] <= b[3]


def cut_contacts(rects):
    """Where two rectangles of one plane face each other and overlap, cut the overlap from both.

    Two rectangles of one plane facing the same way must not overlap (that would be a coincident
    face): asserted.
    """
    planes = {}
    for r in rects:
        r.openings = list(r.holes)  # the holes given before contacts: openings
    for r in rects:
        planes.setdefault(r.key(), []).append(r)
    for group in planes.values():
        if len(group) < 2:
            continue
        for i, a in enumerate(group):
            for b in group[i + 1:]:
                u0, u1 = max(a.u0, b.u0), min(a.u1, b.u1)
                v0, v1 = max(a.v0, b.v0), min(a.v1, b.v1)
                if u1 - u0 <= 1e-9 or v1 - v0 <= 1e-9:
                    continue
                if any(inside((u0, u1, v0, v1), h) for h in a.openings + b.openings):
                    continue  # one of them is cut there already (a light in a ceiling hole)
                assert a.sign != b.sign, f"coincident faces {a.tag}/{b.tag} at {a.key()}"
                a.holes.append((u0, u1, v0, v1))
                b.holes.append((u0, u1, v0, v1))


def rect_pieces(r: Rect):
    """The rectangle minus its holes as few rectangles (u0, u1, v0, v1): rows of free cells
    merged along u, equal runs of consecutive rows merged along v."""
    if not r.holes:
        return [(r.u0, r.u1, r.v0, r.v1)]
    us = sorted({r.u0, r.u1} | {min(max(h[k], r.u0), r.u1) for h in r.holes for k in (0, 1)})
    vs = sorted({r.v0, r.v1} | {min(max(h[k], r.v0), r.v1) for h in r.holes for k in (2, 3)})
    us_a, vs_a = np.array(us), np.array(vs)
    covered = np.zeros((len(vs) - 1, len(us) - 1), dtype=bool)
    for (h0, h1, k0, k1) in r.holes:
        i0, i1 = np.searchsorted(us_a, [max(h0, r.u0), min(h1, r.u1)])
        j0, j1 = np.searchsorted(vs_a, [max(k0, r.v0), min(k1, r.v1)])
        covered[j0:j1, i0:i1] = True
    pieces, open_runs = [], {}
    for j in range(len(vs) - 1):
        runs, i = [], 0
        while i < len(us) - 1:
            if covered[j, i]:
                i += 1
                continue
            k = i
            while k < len(us) - 1 and not covered[j, k]:
                k += 1
            runs.append((i, k))
            i = k
        next_open = {}
        for run in runs:
            next_open[run] = open_runs.pop(run, j)
        for (i, k), j0 in open_runs.items():
            pieces.append((us[i], us[k], vs[j0], vs[j]))
        open_runs = next_open
    for (i, k), j0 in open_runs.items():
        pieces.append((us[i], us[k], vs[j0], vs[-1]))
    return pieces


def rect_polys(r: Rect):
    """The finished polygons of a rectangle (after its holes are cut)."""
    out = []
    u, v = (r.axis + 1) % 3, (r.axis + 2) % 3
    for (u0, u1, v0, v1) in rect_pieces(r):
        corners = [(u0, v0), (u1, v0), (u1, v1), (u0, v1)]
        if r.sign < 0:
            corners.reverse()
        verts = []
        for (a, b) in corners:
            p = [0.0, 0.0, 0.0]
            p[r.axis], p[u], p[v] = r.coord, a, b
            verts.append(tuple(p))
        out.append(Poly(verts, r.material, r.tag))
    return out


def rotate_y(p, angle, pivot):
    """``p`` turned by ``angle`` (radians, counter-clockwise seen from above) about the vertical
    through ``pivot`` (x, z), then moved so the local origin sits at the pivot."""
    c, s = math.cos(angle), math.sin(angle)
    x, y, z = p
    return (r6(pivot[0] + c * x + s * z), r6(y), r6(pivot[1] - s * x + c * z))


@dataclass
class Assembly:
    """Axis-aligned boxes in a local frame, turned about the vertical and placed on the floor.

    Contacts among its own boxes are cut in the local frame; faces at local y = 0 facing down
    stand on the floor (dropped; the floor is cut around their footprints)."""

    rects: list
    angle: float
    pivot: tuple
    converted: bool = False

    def finish(self):
        """(polygons, footprints): footprints are the turned rectangles (4 corners x, z).
        Converted: nothing cut, bottoms kept and sunk, no footprints."""
        if self.converted:
            for r in self.rects:
                sink(r)
        else:
            cut_contacts(self.rects)
        polys, feet = [], []
        for r in self.rects:
            if not self.converted and r.axis == 1 and r.sign < 0 and r.coord == 0.0:
                corners = [(r.v0, r.u0), (r.v1, r.u0), (r.v1, r.u1), (r.v0, r.u1)]  # (x, z)
                feet.append([rotate_y((x, 0.0, z), self.angle, self.pivot) for x, z in corners])
                continue
            for p in rect_polys(r):
                polys.append(Poly([rotate_y(q, self.angle, self.pivot) for q in p.verts],
                                  p.material, p.tag))
        return polys, feet


def sink(r: Rect):
    """A furniture face at or from the floor (y = 0) moved or stretched SINK into it."""
    if r.axis == 1:
        if r.coord == 0.0:
            r.coord = -SINK
    elif r.axis == 0:  # u = y
        if r.u0 == 0.0:
            r.u0 = -SINK
    elif r.v0 == 0.0:  # axis 2: v = y
        r.v0 = -SINK


def footprint_fill(foot, material, tag):
    """The floor between a turned footprint and its bounding box: four triangles facing up.
    Returns (bounding box as a hole in the floor rect's u, v = z, x), triangles."""
    xs = [p[0] for p in foot]
    zs = [p[2] for p in foot]
    x0, x1, z0, z1 = min(xs), max(xs), min(zs), max(zs)
    tris = []
    n = len(foot)
    for i in range(n):
        a, b = foot[i], foot[(i + 1) % n]
        for c in ((a[0], 0.0, b[2]), (b[0], 0.0, a[2])):
            if c[0] in (x0, x1) and c[2] in (z0, z1) and c != a and c != b:
                tri = [a, c, b]
                # Face up: (c - a) x (b - a) has +y when counter-clockwise seen from above.
                e1 = (c[0] - a[0], c[2] - a[2])
                e2 = (b[0] - a[0], b[2] - a[2])
                ny = e1[1] * e2[0] - e1[0] * e2[1]
                if abs(ny) < 1e-12:
                    continue
                if ny < 0:
                    tri.reverse()
                tris.append(Poly(tri, material, tag))
                break
    # In the floor rect (axis 1): u = z, v = x.
    return (z0, z1, x0, x1), tris


# --------------------------------------------------------------------------------------------
# Furniture (local frames: x across, z depth, y up; the origin at a floor corner).


def desk_assembly(width=1.4, depth=0.7, top_mat="desk_wood"):
    """A desk on four legs with a monitor, keyboard (keys), mouse, pens, eraser and paper."""
    h, t, leg = 0.75, 0.03, 0.05
    rects = []
    for lx in (0.02, width - 0.02 - leg):
        for lz in (0.02, depth - 0.02 - leg):
            rects += box(lx, lx + leg, 0, h - t, lz, lz + leg, "metal", "desk")
    rects += box(0, width, h - t, h, 0, depth, top_mat, "desk")
    y = h
    # Monitor: base plate, neck, screen box, screen face (a separate material in front).
    mx = width / 2
    rects += box(mx - 0.11, mx + 0.11, y, y + 0.012, 0.08, 0.26, "plastic_dark", "monitor")
    rects += box(mx - 0.02, mx + 0.02, y + 0.012, y + 0.25, 0.14, 0.17, "plastic_dark", "monitor")
    rects += box(mx - 0.3, mx + 0.3, y + 0.25, y + 0.6, 0.12, 0.19, "plastic_dark", "monitor")
    rects += box(mx - 0.28, mx + 0.28, y + 0.27, y + 0.58, 0.19, 0.196, "screen", "monitor")
    # Keyboard with keys (small boxes 1.6 x 0.8 x 1.6 cm on 1.9 cm pitch).
    kx0, kz0, kw, kd, kh = mx - 0.23, 0.40, 0.46, 0.16, 0.02
    rects += box(kx0, kx0 + kw, y, y + kh, kz0, kz0 + kd, "plastic_light", "keyboard")
    for row in range(6):
        for col in range(22):
            x = kx0 + 0.018 + col * 0.019
            z = kz0 + 0.012 + row * 0.023
            rects += box(x, x + 0.016, y + kh, y + kh + 0.008, z, z + 0.016, "key", "keys")
    # Mouse, paper stack, pens, eraser, a cup-like box.
    rects += box(mx + 0.32, mx + 0.38, y, y + 0.03, 0.45, 0.55, "plastic_dark", "mouse")
    rects += box(0.08, 0.29, y, y + 0.02, 0.35, 0.65, "paper", "paper")
    for k in range(4):
        x = 0.33 + 0.02 * k
        rects += box(x, x + 0.01, y, y + 0.01, 0.45 + 0.01 * k, 0.59 + 0.01 * k,
                     ("pen_red", "pen_blue", "plastic_dark", "pen_red")[k], "pens")
    rects += box(0.45, 0.47, y, y + 0.01, 0.62, 0.635, "eraser", "eraser")
    rects += box(width - 0.2, width - 0.12, y, y + 0.1, 0.15, 0.23, "cup", "cup")
    return rects


def chair_assembly(seat_mat="fabric_blue"):
    """A chair: four legs, a seat, two back posts and a backrest (0.46 x 0.46 m)."""
    w, d, leg, sy, st = 0.46, 0.46, 0.035, 0.42, 0.05
    rects = []
    for lx in (0.0, w - leg):
        for lz in (0.0, d - leg):
            rects += box(lx, lx + leg, 0, sy, lz, lz + leg, "metal", "chair")
    rects += box(0, w, sy, sy + st, 0, d, seat_mat, "chair")
    for lx in (0.02, w - 0.02 - 0.03):
        rects += box(lx, lx + 0.03, sy + st, sy + st + 0.22, 0.01, 0.04, "metal", "chair")
    rects += box(0.0, w, sy + st + 0.22, sy + st + 0.5, 0.0, 0.05, seat_mat, "chair")
    return rects


def table_assembly(width, depth, top_mat, height=0.74):
    """A table on four legs."""
    t, leg = 0.04, 0.06
    rects = []
    for lx in (0.05, width - 0.05 - leg):
        for lz in (0.05, depth - 0.05 - leg):
            rects += box(lx, lx + leg, 0, height - t, lz, lz + leg, "metal", "table")
    rects += box(0, width, height - t, height, 0, depth, top_mat, "table")
    return rects


BOOK_MATS = ("book_red", "book_green", "book_blue", "book_cream", "book_pattern", "book_dark")


def bookshelf_assembly(rng, width=0.9, depth=0.3, height=2.0, boards=5, fill=0.92):
    """A bookshelf (sides, top, plinth, back, boards) full of books with gaps of 0-8 mm; the
    back panel is at local z = 0 (its back face touches the wall when placed against one)."""
    side, board_t, back_t = 0.02, 0.02, 0.01
    rects = []
    rects += box(0, side, 0, height, 0, depth, "shelf_wood", "shelf")
    rects += box(width - side, width, 0, height, 0, depth, "shelf_wood", "shelf")
    rects += box(side, width - side, 0, height, 0, back_t, "shelf_wood", "shelf")
    rects += box(side, width - side, 0, 0.08, back_t, depth, "shelf_wood", "shelf")  # plinth
    rects += box(side, width - side, height - board_t, height, back_t, depth, "shelf_wood",
                 "shelf")
    levels = [0.08 + k * (height - 0.08 - board_t) / boards for k in range(boards + 1)]
    for k in range(1, boards):
        y = levels[k]
        rects += box(side, width - side, y - board_t, y, back_t, depth, "shelf_wood", "shelf")
    for k in range(boards):
        y0 = levels[k]
        space = levels[k + 1] - (board_t if k + 1 < boards else board_t) - y0
        x = side + rng.choice((0.0, 0.004, 0.01))
        while True:
            thick = rng.choice((0.012, 0.015, 0.018, 0.02, 0.025, 0.03, 0.04))
            if x + thick > side + (width - 2 * side) * fill:
                break
            tall = min(space - 0.02, rng.uniform(0.17, 0.30))
            deep = rng.uniform(0.14, depth - back_t - 0.01)
            z0 = back_t + rng.choice((0.0, 0.005, 0.02))
            rects += box(x, x + thick, y0, y0 + tall, z0, min(z0 + deep, depth - 0.005),
                         rng.choice(BOOK_MATS), "books")
            x += thick + rng.choice((0.0, 0.0, 0.002, 0.004, 0.008))
        # A small box or two on some boards.
        if k % 2 == 1 and x + 0.06 < width - side:
            rects += box(x + 0.01, x + 0.05, y0, y0 + 0.03, 0.15, 0.19, "eraser", "smallbox")
    return rects


def cabinet_assembly(width=0.5, depth=0.6, height=1.3, drawers=4):
    """A filing cabinet: a box standing on the floor, drawer fronts and small handles."""
    rects = box(0, width, 0, height, 0, depth, "metal", "cabinet")
    dh = height / drawers
    for k in range(drawers):
        y0 = k * dh + 0.01
        rects += box(0.015, width - 0.015, y0, y0 + dh - 0.02, depth, depth + 0.01,
                     "plastic_light", "cabinet")
        hy = y0 + dh * 0.7
        rects += box(width / 2 - 0.05, width / 2 + 0.05, hy, hy + 0.015, depth + 0.01,
                     depth + 0.03, "metal", "handle")
    return rects


def brick_tray(x0, y0, z0, seed=7):
    """A tray of 1.5 cm bricks (on a table top at height y0)."""
    rects = box(x0, x0 + 0.3, y0, y0 + 0.01, z0, z0 + 0.2, "plastic_dark", "tray")
    rng = random.Random(seed)
    for i in range(12):
        for j in range(8):
            if rng.random() < 0.6:
                x, z = x0 + 0.01 + i * 0.0235, z0 + 0.01 + j * 0.0235
                rects += box(x, x + 0.015, y0 + 0.01, y0 + 0.01 + rng.choice((0.01, 0.02)), z,
                             z + 0.015, rng.choice(("pen_red", "pen_blue", "book_cream")), "bricks")
    return rects


def laptop_polys(x0, y0, z0, angle_deg=105.0):
    """A laptop on a table: a base box (cut into the table by contact) and a lid leaning back
    (a box turned about x around the base's back-top edge): skew faces touching nothing."""
    w, d, t = 0.32, 0.22, 0.015
    base = box(x0, x0 + w, y0, y0 + t, z0, z0 + d, "plastic_dark", "laptop")
    tilt = math.radians(angle_deg - 90.0)
    c, s = math.cos(tilt), math.sin(tilt)
    lid_h, lid_t = 0.21, 0.008
    polys = []
    # The lid in a frame where its back-bottom edge is at the origin, standing up along +y with
    # its thickness along +z; turned so its top leans back (towards -z).
    for r in box(0, w, 0, lid_h, 0, lid_t, "plastic_dark", "laptop_lid"):
        for p in rect_polys(r):
            verts = []
            for (x, y, z) in p.verts:
                yy, zz = y * c + z * s, -y * s + z * c
                verts.append((r6(x0 + x), r6(y0 + t + 0.002 + yy), r6(z0 + zz)))
            polys.append(Poly(verts, p.material, p.tag))
    return base, polys


# --------------------------------------------------------------------------------------------
# The two rooms.


def build(seed=1, converted=False, without=frozenset()):
    """All polygons of the scene, each tagged with the room shell or object it belongs to
    (``converted``: the converted style of the module's docstring, but its features named in
    ``without``, :data:`FEATURES`)."""
    contacts, luminaires, solids = (converted and f not in without
                                    for f in ("contacts", "luminaires", "solids"))
    rng = random.Random(seed)
    rects, polys, feet = [], [], []
    z0, z1 = Z_RANGE

    # Room shells.
    a_shell = shell(A_X[0], A_X[1], 0, HEIGHT, z0, z1,
                    {"floor": "floor_wood", "ceiling": "ceiling", "wall": "wall_plaster"}, "shellA")
    b_shell = shell(B_X[0], B_X[1], 0, HEIGHT, z0, z1,
                    {"floor": "carpet", "ceiling": "ceiling", "wall": "wall_green"}, "shellB")
    # Doorway through the shared wall: holes in both walls (u = y, v = z for axis x).
    for r in a_shell + b_shell:
        if r.axis == 0 and r.coord in (A_X[1], B_X[0]):
            r.holes.append((0.0, DOOR_TOP, DOOR_Z[0], DOOR_Z[1]))
    # Reveals of the doorway: jambs, head and the floor in it.
    rects.append(Rect(2, DOOR_Z[0], 1, A_X[1], B_X[0], 0.0, DOOR_TOP, "wall_plaster", "door"))
    rects.append(Rect(2, DOOR_Z[1], -1, A_X[1], B_X[0], 0.0, DOOR_TOP, "wall_plaster", "door"))
    rects.append(Rect(1, DOOR_TOP, -1, DOOR_Z[0], DOOR_Z[1], A_X[1], B_X[0], "wall_plaster",
                      "door"))
    rects.append(Rect(1, 0.0, 1, DOOR_Z[0], DOOR_Z[1], A_X[1], B_X[0], "floor_wood", "door"))
    # Window in room A's back wall (z = -5): a recess 0.15 m deep closed by a dark pane.
    wx, wy = (1.8, 4.2), (0.9, 2.2)
    wz = z0 - 0.15
    for r in a_shell:
        if r.axis == 2 and r.coord == z0:
            r.holes.append((wx[0], wx[1], wy[0], wy[1]))  # axis z: u = x, v = y
    rects.append(Rect(2, wz, 1, wx[0], wx[1], wy[0], wy[1], "glass", "window"))
    rects.append(Rect(0, wx[0], 1, wy[0], wy[1], wz, z0, "wall_plaster", "window"))
    rects.append(Rect(0, wx[1], -1, wy[0], wy[1], wz, z0, "wall_plaster", "window"))
    rects.append(Rect(1, wy[0], 1, wz, z0, wx[0], wx[1], "sill", "window"))
    rects.append(Rect(1, wy[1], -1, wz, z0, wx[0], wx[1], "wall_plaster", "window"))
    # Ceiling lights: emitters flush in holes in the ceiling, facing down (axis y: u = z, v = x).
    lights = [("lamp_a1", (1.2, 2.4), (-1.8, -1.5)), ("lamp_a1", (3.6, 4.8), (-1.8, -1.5)),
              ("lamp_a2", (1.2, 2.4), (-3.8, -3.5)), ("lamp_a2", (3.6, 4.8), (-3.8, -3.5)),
              ("lamp_b", (7.6, 8.8), (-2.7, -2.3))]
    for k, (name, (lx0, lx1), (lz0, lz1)) in enumerate(lights):
        # Which luminaire this is as exported (the boxes, the hung panels, the face under the
        # ceiling); `--without boxes` or `--without panels` makes that kind flush again.
        kind = "boxes" if k < 2 else "panels" if k < 4 else "luminaires"
        if luminaires and kind not in without:
            if k < 2:  # a closed box: emitting bottom, metal housing lying on the ceiling
                for r in box(lx0, lx1, HEIGHT - 0.06, HEIGHT, lz0, lz1, "metal", "light"):
                    if r.axis == 1 and r.sign < 0:
                        r.material = name
                    rects.append(r)
            elif k < 4:  # a thin panel hung 0.3 m down, every face of it emitting
                for r in box(lx0, lx1, HEIGHT - 0.32, HEIGHT - 0.3, lz0, lz1, name, "light"):
                    if "panel-tops" in without and r.axis == 1 and r.sign > 0:
                        r.material = "metal"  # `--without panel-tops`: a top that does not emit
                    rects.append(r)
            else:  # one downward face just under the ceiling
                rects.append(Rect(1, HEIGHT - 0.02, -1, lz0, lz1, lx0, lx1, name, "light"))
            continue
        owner = a_shell if lx0 < A_X[1] else b_shell
        for r in owner:
            if r.axis == 1 and r.sign < 0:
                r.holes.append((lz0, lz1, lx0, lx1))
        rects.append(Rect(1, HEIGHT, -1, lz0, lz1, lx0, lx1, name, "light"))
    rects += a_shell + b_shell

    # Room A furniture.
    def place(local, angle_deg, pivot):
        """A turned assembly: its polygons and footprints."""
        p, f = Assembly(local, math.radians(angle_deg), pivot, contacts).finish()
        polys.extend(p)
        feet.extend(f)

    def put(local, dx, dz, mirror_z=False):
        """An unturned assembly moved by (dx, dz): its rects join the global contact cut.
        With mirror_z, local z maps to dz - z (its local front, +z, then looks towards -z)."""
        for r in local:
            u, v = (r.axis + 1) % 3, (r.axis + 2) % 3
            lo, hi = [0.0] * 3, [0.0] * 3
            lo[r.axis] = hi[r.axis] = r.coord
            lo[u], hi[u], lo[v], hi[v] = r.u0, r.u1, r.v0, r.v1
            lo = [lo[0] + dx, lo[1], lo[2] + dz]
            hi = [hi[0] + dx, hi[1], hi[2] + dz]
            sign = r.sign
            if mirror_z:
                lo[2], hi[2] = 2 * dz - hi[2], 2 * dz - lo[2]
                if r.axis == 2:
                    sign = -sign
            lo, hi = [r6(c) for c in lo], [r6(c) for c in hi]
            moved = Rect(r.axis, lo[r.axis], sign, lo[u], hi[u], lo[v], hi[v], r.material, r.tag)
            if contacts:
                sink(moved)
            rects.append(moved)

    # Desks in two rows, monitors towards +z (the front wall) in both; chairs behind them.
    put(desk_assembly(), 0.4, -0.15, mirror_z=True)
    put(desk_assembly(), 2.3, -0.15, mirror_z=True)
    put(desk_assembly(top_mat="desk_white"), 0.4, -2.6, mirror_z=True)
    put(desk_assembly(), 2.3, -2.6, mirror_z=True)
    put(chair_assembly(), 0.87, -1.45)
    place(chair_assembly("fabric_red"), 25.0, (2.75, -1.6))
    put(chair_assembly("fabric_red"), 0.85, -3.95)
    place(chair_assembly(), -30.0, (2.8, -4.1))
    meeting = table_assembly(1.6, 0.9, "desk_wood")
    meeting += brick_tray(0.2, 0.74, 0.3, seed=11) + brick_tray(1.0, 0.74, 0.45, seed=12)
    place(meeting, 20.0, (4.0, -2.3))
    # Bookshelves against the back wall (their backs touch it), left of the window.
    for x in (0.1, 0.9):
        put(bookshelf_assembly(rng, width=0.8), x, z0)
    put(cabinet_assembly(), 5.3, -4.9)
    # A bookshelf along the left wall between the desk rows, turned to face +x, 5 cm off it.
    place(bookshelf_assembly(rng, width=0.9), 90.0, (0.05, -1.55))

    # Room B furniture: a reading table with laptops and bricks, chairs, four bookshelves.
    tx, tz, tw, td = 7.4, -3.2, 1.8, 0.9
    put(table_assembly(tw, td, "desk_white"), tx, tz)
    ty = 0.74
    for lx, lz, angle in ((tx + 0.2, tz + 0.45, 105.0), (tx + 1.2, tz + 0.5, 112.0)):
        base, lid = laptop_polys(lx, ty, lz, angle_deg=angle)
        rects.extend(base)
        polys.extend(lid)
    rects.extend(brick_tray(tx + 0.7, ty, tz + 0.1))
    put(chair_assembly("fabric_blue"), tx + 0.3, -1.3, mirror_z=True)
    place(chair_assembly("fabric_blue"), 160.0, (tx + 1.5, tz - 0.1))
    place(chair_assembly("fabric_red"), 200.0, (tx + 0.9, tz - 0.25))
    for x in (6.3, 7.25, 8.2, 9.15):
        put(bookshelf_assembly(rng, width=0.9, height=2.2, boards=6), x, z0)
    # Three more along the right wall, turned to face -x, 2 cm off it.
    for z in (-4.6, -3.65, -2.7):
        place(bookshelf_assembly(rng, width=0.9, height=2.2, boards=6), -90.0, (10.18, z))

    # Footprints of turned assemblies: cut out of the floor by their bounding box, filled.
    for foot in feet:
        owner = a_shell if max(p[0] for p in foot) < A_X[1] else b_shell
        floor = next(r for r in owner if r.axis == 1 and r.sign > 0)
        hole, tris = footprint_fill(foot, floor.material, floor.tag)
        floor.holes.append(hole)
        polys.extend(tris)

    if solids:
        # A partition built as two overlapping boxes (their faces inside each other) and a
        # column through the floor and the ceiling: buried faces, as IFC solids leave them.
        rects += box(5.2, 5.32, -0.05, 2.0, -3.4, -2.2, "wall_plaster", "partition")
        rects += box(5.2, 5.32, -0.05, 2.0, -2.6, -1.6, "wall_plaster", "partition")
        rects += box(3.0, 3.3, -0.1, HEIGHT + 0.1, -0.6, -0.3, "wall_plaster", "column")
    if contacts:
        for r in rects:
            r.openings = list(r.holes)
    else:
        cut_contacts(rects)
    for r in rects:
        polys.extend(rect_polys(r))
    return polys


# --------------------------------------------------------------------------------------------
# Materials and textures.


def png_bytes(rgb: np.ndarray) -> bytes:
    """An 8-bit RGB PNG of ``rgb`` (height x width x 3, uint8), written with zlib alone."""
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[y].tobytes() for y in range(h))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def textures():
    """The scene's textures (name -> uint8 image), procedural and deterministic."""
    rng = np.random.default_rng(3)
    n = 64
    y, x = np.mgrid[0:n, 0:n]
    out = {}
    # Wooden floor boards: stripes of varying brown with grain.
    board = (x // 16)
    shade = np.array([0.0, 18.0, -12.0, 8.0])[board % 4]
    grain = 10 * np.sin(y / 3.0 + board * 1.7)
    base = np.stack([150 + shade + grain, 105 + shade + grain * 0.8, 65 + shade * 0.6 + grain * 0.5], -1)
    out["wood_floor.png"] = base
    # Desk veneer: lighter wood.
    grain = 14 * np.sin(x / 2.5 + 0.3 * np.sin(y / 5.0))
    out["wood_desk.png"] = np.stack([190 + grain, 150 + grain, 105 + grain * 0.7], -1)
    # Carpet: blue-grey noise.
    noise = rng.normal(0, 18, (n, n))
    out["carpet.png"] = np.stack([120 + noise, 130 + noise, 150 + noise], -1)
    # Book cover pattern: checks of two colours.
    check = ((x // 8 + y // 8) % 2).astype(float)
    out["book_pattern.png"] = np.stack([170 * check + 40, 60 + 40 * check, 50 + 20 * check], -1)
    return {k: np.clip(v, 0, 255).astype(np.uint8) for k, v in out.items()}


# name -> (Kd, texture or None, Ke or None)
MATERIALS = {
    "wall_plaster": ((0.78, 0.76, 0.72), None, None),
    "wall_green": ((0.55, 0.66, 0.55), None, None),
    "ceiling": ((0.85, 0.85, 0.85), None, None),
    "floor_wood": ((1.0, 1.0, 1.0), "wood_floor.png", None),
    "carpet": ((1.0, 1.0, 1.0), "carpet.png", None),
    "desk_wood": ((1.0, 1.0, 1.0), "wood_desk.png", None),
    "desk_white": ((0.8, 0.8, 0.78), None, None),
    "shelf_wood": ((0.9, 0.9, 0.9), "wood_desk.png", None),
    "sill": ((0.7, 0.7, 0.7), None, None),
    "glass": ((0.04, 0.04, 0.05), None, None),
    "metal": ((0.5, 0.5, 0.52), None, None),
    "plastic_dark": ((0.08, 0.08, 0.09), None, None),
    "plastic_light": ((0.7, 0.7, 0.68), None, None),
    "screen": ((0.03, 0.03, 0.04), None, None),
    "key": ((0.15, 0.15, 0.16), None, None),
    "paper": ((0.85, 0.85, 0.82), None, None),
    "pen_red": ((0.6, 0.08, 0.06), None, None),
    "pen_blue": ((0.08, 0.12, 0.6), None, None),
    "eraser": ((0.75, 0.55, 0.5), None, None),
    "cup": ((0.8, 0.78, 0.7), None, None),
    "fabric_blue": ((0.15, 0.2, 0.4), None, None),
    "fabric_red": ((0.5, 0.1, 0.1), None, None),
    "book_red": ((0.55, 0.1, 0.08), None, None),
    "book_green": ((0.1, 0.35, 0.15), None, None),
    "book_blue": ((0.1, 0.15, 0.45), None, None),
    "book_cream": ((0.8, 0.75, 0.6), None, None),
    "book_pattern": ((1.0, 1.0, 1.0), "book_pattern.png", None),
    "book_dark": ((0.06, 0.05, 0.05), None, None),
    # Lights: emitted radiance Ke in W/sr/m^2 (E = pi Ke), no reflection.
    "lamp_a1": ((0.0, 0.0, 0.0), None, (14.0, 14.0, 13.0)),
    "lamp_a2": ((0.0, 0.0, 0.0), None, (14.0, 13.5, 12.0)),
    "lamp_b": ((0.0, 0.0, 0.0), None, (18.0, 17.0, 15.0)),
}


def write_mtl(path: Path):
    lines = ["# Materials of the furnished scenes (scripts/radiance/furnished.py).",
             "# Kd: reflectance (x the mean linear colour of map_Kd); Ke: emitted radiance,",
             "# W/sr/m^2 (a light's radiosity is E = pi Ke).", ""]
    for name, (kd, tex, ke) in MATERIALS.items():
        lines.append(f"newmtl {name}")
        lines.append("Kd {:g} {:g} {:g}".format(*kd))
        if tex:
            lines.append(f"map_Kd {tex}")
        if ke:
            lines.append("Ke {:g} {:g} {:g}".format(*ke))
        lines.append("")
    path.write_text("\n".join(lines))


# --------------------------------------------------------------------------------------------
# Writing the variants.


def fan(verts, first=0):
    """A polygon as fan triangles from its vertex ``first`` (triangles keep its winding)."""
    if len(verts) == 3:
        return [verts]
    vs = verts[first:] + verts[:first]
    return [[vs[0], vs[k], vs[k + 1]] for k in range(1, len(vs) - 1)]


def variant_faces(polys, variant, converted=False):
    """The faces (vertex lists, material) of a variant, in writing order. Converted: fan
    triangles, the doubled copy fanned from the next vertex (the other diagonal of a quad);
    ``mixed`` flips 30 % of the non-emitting polygons (seeded)."""
    out = []
    rng = random.Random(24)
    for p in polys:
        verts = p.verts
        if variant == "inside-out" and p.tag == "shellB":
            verts = verts[::-1]
        lamp = MATERIALS[p.material][2] is not None
        if variant == "mixed" and not lamp and rng.random() < 0.3:
            verts = verts[::-1]
        if not converted:
            out.append((verts, p.material))
            if variant == "doubled":
                out.append((verts[::-1], p.material))
            continue
        out += [(t, p.material) for t in fan(verts)]
        if variant == "doubled" and not lamp:
            out += [(t, p.material) for t in fan(verts[::-1], 1)]
    return out


def write_obj(path: Path, faces, mtl_name: str, variant: str):
    """OBJ with shared vertices (positions deduplicated), grouped by material."""
    index, vlines, flines = {}, [], []
    current = None
    for verts, mat in sorted(faces, key=lambda f: f[1]):
        if mat != current:
            flines.append(f"usemtl {mat}")
            current = mat
        ids = []
        for v in verts:
            if v not in index:
                index[v] = len(index) + 1
                vlines.append("v {:g} {:g} {:g}".format(*v))
            ids.append(str(index[v]))
        flines.append("f " + " ".join(ids))
    header = [
        f"# Furnished office and library (scripts/radiance/furnished.py), variant '{variant}'.",
        "# Metres, y up. Two closed rooms sharing a wall with a doorway; five ceiling lights.",
        f"# {len(faces)} faces.",
        f"mtllib {mtl_name}",
    ]
    path.write_text("\n".join(header + vlines + flines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=Path("out/furnished"), help="output folder")
    ap.add_argument("--variant", choices=CONVERTED_VARIANTS + ("all",), default="all")
    ap.add_argument("--style", choices=("clean", "converted", "both"), default="clean",
                    help="clean (furnished-*.obj) or converted (converted-*.obj): see above")
    ap.add_argument("--seed", type=int, default=1, help="seed of the furniture's variations")
    ap.add_argument("--without", action="append", default=[], choices=FEATURES,
                    help="converted style: leave this feature out (repeatable); the files are "
                    "then converted-VARIANT-no-FEATURE.obj")
    args = ap.parse_args()
    if args.without and args.style != "converted":
        ap.error("--without applies to --style converted")
    if "contacts" in args.without and "solids" not in args.without:
        ap.error("--without contacts needs --without solids too: the column stands where "
                 "only uncut contacts leave the faces it meets alone")
    without = frozenset(args.without)
    suffix = "".join(f"-no-{f}" for f in FEATURES if f in without)

    args.out.mkdir(parents=True, exist_ok=True)
    for name, img in textures().items():
        (args.out / name).write_bytes(png_bytes(img))
    write_mtl(args.out / "furnished.mtl")
    styles = ("clean", "converted") if args.style == "both" else (args.style,)
    for style in styles:
        converted = style == "converted"
        polys = build(args.seed, converted, without)
        every = CONVERTED_VARIANTS if converted else VARIANTS
        variants = every if args.variant == "all" else (args.variant,)
        for variant in variants:
            if variant not in every:
                ap.error(f"--variant {variant} is not made in the {style} style")
            faces = variant_faces(polys, variant, converted and "triangles" not in without)
            stem = "converted" if converted else "furnished"
            path = args.out / f"{stem}-{variant}{suffix}.obj"
            write_obj(path, faces, "furnished.mtl", f"converted {variant}" if converted else variant)
            print(f"{path}: {len(faces)} faces")


if __name__ == "__main__":
    main()
