#!/usr/bin/env python3
"""Write the CalculiX reference decks: a clamped, sheared aluminium block in each solid element
type, and a block driving a mass on springs through a rigid coupling.

The mesh is built here independently of stickslip's generator (own node numbering, own
tetrahedral split), and the block is sheared (y += 0.15 x z / H, so elements are not
parallelepipeds and quadratic edges are curved) so that the comparison exercises general
element geometry.
"""
import itertools
import os

L, W, H = 0.2, 0.04, 0.03
E, NU, RHO = 70e9, 0.33, 2700.0
HERE = os.path.dirname(os.path.abspath(__file__))


def position(i, j, k, n):
    x, y, z = L * i / n[0], W * j / n[1], H * k / n[2]
    return x, y + 0.15 * x * z / H, z


def lattice(cells, order):
    dims = [order * c + 1 for c in cells]
    ids = {}
    for k in range(dims[2]):
        for j in range(dims[1]):
            for i in range(dims[0]):
                ids[(i, j, k)] = 100 + len(ids) + 1  # ids start at 101: not the element ids
    return dims, ids


HEX_CORNERS = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
HEX_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]
TET_EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]


def signed_volume(a, b, c, d):
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    w = [d[i] - a[i] for i in range(3)]
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
            + u[2] * (v[0] * w[1] - v[1] * w[0]))


def elements(kind, cells):
    order = 2 if kind in ("C3D10", "C3D20", "C3D20R") else 1
    dims, ids = lattice(cells, order)
    used, elems = set(), []
    for ci, cj, ck in itertools.product(range(cells[0]), range(cells[1]), range(cells[2])):
        base = (order * ci, order * cj, order * ck)
        pt = lambda c: tuple(base[d] + order * c[d] for d in range(3))
        if kind.startswith("C3D8") or kind.startswith("C3D20"):
            corners = [pt(c) for c in HEX_CORNERS]
            nodes = corners + ([tuple((corners[a][d] + corners[b][d]) // 2 for d in range(3)) for a, b in HEX_EDGES]
                               if order == 2 else [])
            elems.append(nodes)
        else:
            # Split each cell into 6 tetrahedra around the diagonal (0,0,0)-(1,1,1).
            for p in itertools.permutations(range(3)):
                c = [[0, 0, 0] for _ in range(4)]
                c[1][p[0]] = 1
                c[2] = list(c[1])
                c[2][p[1]] = 1
                c[3] = [1, 1, 1]
                corners = [pt(x) for x in c]
                xyz = [position(*q, [order * n for n in cells]) for q in corners]
                if signed_volume(*xyz) < 0:
                    corners[1], corners[2] = corners[2], corners[1]
                nodes = corners + ([tuple((corners[a][d] + corners[b][d]) // 2 for d in range(3)) for a, b in TET_EDGES]
                                   if order == 2 else [])
                elems.append(nodes)
    for e in elems:
        used.update(e)
    fine = [order * n for n in cells]
    nodes = sorted((ids[p], position(*p, fine), p) for p in used)
    return nodes, [[ids[p] for p in e] for e in elems]


def write_nodes(f, nodes):
    f.write("*NODE, NSET=NALL\n")
    for nid, (x, y, z), _ in nodes:
        f.write(f"{nid}, {x!r}, {y!r}, {z!r}\n")


def write_elements(f, kind, elems):
    f.write(f"*ELEMENT, TYPE={kind}, ELSET=EALL\n")
    for eid, e in enumerate(elems, start=1):
        fields = [str(eid)] + [str(n) for n in e]
        # At most 16 entries per line; a trailing comma continues the element.
        for start in range(0, len(fields), 16):
            chunk = fields[start:start + 16]
            more = start + 16 < len(fields)
            f.write(", ".join(chunk) + ("," if more else "") + "\n")


def material(f):
    f.write(f"*MATERIAL, NAME=ALU\n*ELASTIC\n{E!r}, {NU!r}\n*DENSITY\n{RHO!r}\n")
    f.write("*SOLID SECTION, ELSET=EALL, MATERIAL=ALU\n")


def step(f, modes):
    f.write(f"*STEP\n*FREQUENCY\n{modes}\n*END STEP\n")


def clamped_deck(kind, cells):
    nodes, elems = elements(kind, cells)
    with open(os.path.join(HERE, f"block_{kind.lower()}.inp"), "w") as f:
        f.write(f"** Clamped sheared aluminium block, {kind}, cells {cells}\n")
        write_nodes(f, nodes)
        write_elements(f, kind, elems)
        f.write("*NSET, NSET=CLAMP\n")
        clamp = [nid for nid, _, p in nodes if p[0] == 0]
        for start in range(0, len(clamp), 8):
            f.write(", ".join(map(str, clamp[start:start + 8])) + "\n")
        material(f)
        f.write("*BOUNDARY\nCLAMP, 1, 3\n")
        step(f, 10)


def coupled_deck():
    """Clamped C3D8 block whose free end is rigidly coupled to a reference node (CalculiX's
    *KINEMATIC takes DOFs 1-3 only: the coupled translations follow the reference node's rigid
    motion, rotations included); that node is
    tied by three SPRING2 connectors to a node carrying a point mass, held by SPRING1 springs
    to ground: the paper's reference-node/connector layout in miniature."""
    cells = (8, 2, 2)
    nodes, elems = elements("C3D8", cells)
    ref, mass_node = 9001, 9002
    with open(os.path.join(HERE, "coupled_c3d8.inp"), "w") as f:
        f.write("** Clamped block, end face rigidly coupled to a reference node, mass on springs\n")
        write_nodes(f, nodes)
        f.write(f"*NODE\n{ref}, {L + 0.01!r}, {0.5 * W + 0.075 * L!r}, {0.5 * H!r}\n")
        f.write(f"{mass_node}, {L + 0.03!r}, {0.5 * W + 0.075 * L!r}, {0.5 * H!r}\n")
        write_elements(f, "C3D8", elems)
        f.write("*NSET, NSET=CLAMP\n" + ", ".join(str(n) for n, _, p in nodes if p[0] == 0) + "\n")
        f.write("*NSET, NSET=TIP\n" + ", ".join(str(n) for n, _, p in nodes if p[0] == cells[0]) + "\n")
        f.write("*SURFACE, NAME=TIPS, TYPE=NODE\nTIP\n")
        f.write(f"*COUPLING, REF NODE={ref}, SURFACE=TIPS, CONSTRAINT NAME=C1\n*KINEMATIC\n1, 3\n")
        f.write(f"*ELEMENT, TYPE=SPRING2, ELSET=LINKX\n9101, {ref}, {mass_node}\n")
        f.write(f"*ELEMENT, TYPE=SPRING2, ELSET=LINKY\n9102, {ref}, {mass_node}\n")
        f.write(f"*ELEMENT, TYPE=SPRING2, ELSET=LINKZ\n9103, {ref}, {mass_node}\n")
        f.write(f"*ELEMENT, TYPE=SPRING1, ELSET=GROUNDZ\n9104, {mass_node}\n")
        f.write(f"*ELEMENT, TYPE=SPRING1, ELSET=GROUNDY\n9105, {mass_node}\n")
        f.write(f"*ELEMENT, TYPE=MASS, ELSET=SHAKER\n9106, {mass_node}\n")
        for name, dof, k in [("LINKX", 1, 1e8), ("LINKY", 2, 1e8), ("LINKZ", 3, 1e8)]:
            f.write(f"*SPRING, ELSET={name}\n{dof}, {dof}\n{k!r}\n")
        # CalculiX reads a real only with a decimal point or an exponent: write 2.e5, not 200000.
        f.write("*SPRING, ELSET=GROUNDZ\n3\n2.e5\n*SPRING, ELSET=GROUNDY\n2\n2.e5\n")
        f.write("*MASS, ELSET=SHAKER\n0.5\n")
        material(f)
        f.write("*BOUNDARY\nCLAMP, 1, 3\n")
        step(f, 10)


if __name__ == "__main__":
    for kind, cells in [("C3D4", (8, 2, 2)), ("C3D10", (5, 2, 2)), ("C3D8", (10, 2, 2)), ("C3D20", (5, 2, 2)),
                        ("C3D20R", (5, 2, 2))]:
        clamped_deck(kind, cells)
    coupled_deck()
