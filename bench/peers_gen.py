#!/usr/bin/env python3
"""Build the constrained Jacobians of trocar's presets and dia10_like in CasADi SX and in SymPy,
from the same geometry (docs/reference-robots.md), and emit C the way a user of those tools would:

* CasADi: ``casadi.Function`` on SX, ``CodeGenerator`` (= ``Function.generate``), once with default
  options and once with the ``cse`` option;
* SymPy: expressions built with ``sympy.Matrix``-style products, ``sympy.cse`` over all outputs, ``ccode``.

Kinematics (docs/reference-robots.md, conventions): link frame k is joint k's frame, g_{k-1,k}(q_k) = Trans(o_k) Rot(a_k, q_k); the
joint's twist in its own frame is (0, a_k) (linear part first). Body Jacobian column k is
Ad_{g_ke}^{-1} (0, a_k). J^r = [Ad_{g_ei} Lambda# | J^B_0e2] (3.15) with the thesis bases (3.23), (3.27).

The kinematics below is written once against plain Python arithmetic on "scalars" that are SymPy
expressions or CasADi SX; literals 0 and 1 are kept as Python ints and folded away (both tools do the
same folding themselves: 0*x = 0 in SymPy and in SX).

The Franka Panda (cases ``panda`` and ``panda_i``) is read from trocar's shipped URDF
(runtime/model/robots/urdf/panda.urdf): joint k is g_{k-1,k}(q_k) = Trans(xyz_k) Rot_rpy(rpy_k) Rot(z, q_k),
the fixed joint panda_joint8 folded into the tip. The fixed rotations Rot_rpy (rpy = +-pi/2 about x,
written 1.5707963267948966) are snapped to exact 0 and +-1 where they are within 1e-12 of them, as
trocar's generator does; without that, both tools would carry products with cos(pi/2) = 6.1e-17.

Two generic robots with a remote centre of motion whose H is not a thesis preset (Lambda# is the
computed basis: Ad_{g_ir} N, N the unit vectors of the free columns of H's reduced row echelon form,
as trocar's derivation and numeric runtime take it; g_ir = (I, (0, l_a, 0))), outputs g_0e,
J^B_0i (6 x 6) and J^r = [Ad_{g_ei} Lambda# | J^B_0e2] (6 x 5), as for dia10_like:

* ``oblique7``: bench/peers-harness/oblique7.toml (written by ``bench/chains.py --peers``), seven
  revolute joints with oblique unit axes and offsets as 17-digit floats, g_{k-1,k} = Trans(o_k)
  Rot(a_k, q_k) with Rodrigues' Rot(a, q) = c I + s [a]x + (1 - c) a a^T, the constraint on link 6
  with H as two explicit rows;
* ``panda_rcm``: bench/peers-harness/panda-link6-rcm.toml, the Panda of the URDF with the
  constraint on panda_link6 (H = x, z) and the end effector at panda_link8.

Usage: peers_gen.py OUTDIR
Writes OUTDIR/casadi_peers.c, OUTDIR/sympy_peers.c, OUTDIR/peers.h, OUTDIR/opcounts.json.
"""

import json
import math
import os
import sys
import time
import xml.etree.ElementTree as ET


# ---------------------------------------------------------------------------------------------
# Generic kinematics on scalars (ints 0/1 folded)

def is_lit(a, v):
    return isinstance(a, int) and a == v


def add(a, b):
    if is_lit(a, 0):
        return b
    if is_lit(b, 0):
        return a
    return a + b


def sub(a, b):
    if is_lit(b, 0):
        return a
    if is_lit(a, 0):
        return neg(b)
    return a - b


def neg(a):
    if is_lit(a, 0):
        return 0
    return -a


def mul(a, b):
    if is_lit(a, 0) or is_lit(b, 0):
        return 0
    if is_lit(a, 1):
        return b
    if is_lit(b, 1):
        return a
    if is_lit(a, -1):
        return neg(b)
    if is_lit(b, -1):
        return neg(a)
    return a * b


def dot(xs, ys):
    acc = 0
    for x, y in zip(xs, ys):
        acc = add(acc, mul(x, y))
    return acc


def matmul3(A, B):
    return [[dot(A[i], [B[k][j] for k in range(3)]) for j in range(3)] for i in range(3)]


def matvec3(A, v):
    return [dot(A[i], v) for i in range(3)]


def transpose3(A):
    return [[A[j][i] for j in range(3)] for i in range(3)]


def cross(a, b):
    return [
        sub(mul(a[1], b[2]), mul(a[2], b[1])),
        sub(mul(a[2], b[0]), mul(a[0], b[2])),
        sub(mul(a[0], b[1]), mul(a[1], b[0])),
    ]


IDENT = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
AXES = {"x": [1, 0, 0], "y": [0, 1, 0], "z": [0, 0, 1]}


def rot(axis, s, c):
    if not isinstance(axis, str):
        return rodrigues(axis, s, c)
    if axis == "x":
        return [[1, 0, 0], [0, c, neg(s)], [0, s, c]]
    if axis == "y":
        return [[c, 0, s], [0, 1, 0], [neg(s), 0, c]]
    if axis == "z":
        return [[c, neg(s), 0], [s, c, 0], [0, 0, 1]]
    raise ValueError(axis)


def rodrigues(a, s, c):
    """Rot(a, q) = c I + s [a]x + (1 - c) a a^T for a float unit axis a (written as a user would:
    t = 1 - c once, then each entry t a_i a_j + c delta_ij + s [a]x_ij)."""
    t = sub(1, c)
    K = [[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]]
    out = []
    for i in range(3):
        row = []
        for j in range(3):
            e = mul(t, a[i] * a[j])
            if i == j:
                e = add(e, c)
            if K[i][j] != 0:
                e = add(e, mul(s, K[i][j]))
            row.append(e)
        out.append(row)
    return out


def axis_vec(a):
    return AXES[a] if isinstance(a, str) else list(a)


def compose(g, h):
    """g h for g = (R, p): (R_g R_h, R_g p_h + p_g)."""
    (Rg, pg), (Rh, ph) = g, h
    return (matmul3(Rg, Rh), [add(a, b) for a, b in zip(matvec3(Rg, ph), pg)])


def ad_inv_apply(g, xi):
    """Ad_g^{-1} xi = (R^T (v - p x w), R^T w)."""
    R, p = g
    v, w = xi[:3], xi[3:]
    Rt = transpose3(R)
    return matvec3(Rt, [sub(a, b) for a, b in zip(v, cross(p, w))]) + matvec3(Rt, w)


def joint_tf(origin, axis, s, c):
    return (rot(axis, s, c), list(origin))


def body_jacobian_cols(tfs, axes, tip):
    """Columns Ad_{g_ke}^{-1} (0, a_k) for a chain g_{k-1,k} = tfs[k] and tip transform g_{n,e}."""
    cols = [None] * len(tfs)
    g_ke = tip
    for k in range(len(tfs) - 1, -1, -1):
        cols[k] = ad_inv_apply(g_ke, [0, 0, 0] + axis_vec(axes[k]))
        g_ke = compose(tfs[k], g_ke)
    return cols


def lambda_sharp(kind, la):
    inv_la = 1 / la
    if kind == "uni":  # (3.23)
        return [
            [1, 0, 0, 0, 0, inv_la],
            [0, 1, 0, 0, 0, 0],
            [0, 0, 1, 0, 0, 0],
            [0, 0, 0, 1, 0, 0],
            [0, 0, 0, 0, 1, 0],
        ]
    # (3.27)
    return [
        [1, 0, 0, 0, 0, inv_la],
        [0, 1, 0, 0, 0, 0],
        [0, 0, 1, neg(inv_la), 0, 0],
        [0, 0, 0, 0, 1, 0],
    ]


def constrained_jacobian(after_tfs, after_axes, tip, kind, la):
    """J^r columns: Ad_{g_ei} Lambda# (= Ad_{g_ie}^{-1} Lambda#) then J^B_0e2."""
    g_ie = tip
    for t in reversed(after_tfs):
        g_ie = compose(t, g_ie)
    cols = [ad_inv_apply(g_ie, col) for col in lambda_sharp(kind, la)]
    return cols + body_jacobian_cols(after_tfs, after_axes, tip)


def preset(name, S, C, la, lb, l8):
    """J^r of a preset (docs/reference-robots.md) from (sin, cos) of q7, q8. Returns columns."""
    wrist = {"uni": "y", "bzy": "y", "bzx": "x"}[name]
    kind = "uni" if name == "uni" else "bi"
    tfs = [joint_tf([0, add(la, lb), 0], "z", S[0], C[0]), joint_tf([0, 0, 0], wrist, S[1], C[1])]
    tip = (IDENT, [0, l8, 0])
    return constrained_jacobian(tfs, ["z", wrist], tip, kind, la)


DIA_ORIGINS = [
    [0, 0, 0], [0.194, 0, 1.037], [0, 0.38, 0], [0, 0, 0],
    [0, 0.39, 0], [0, 0, 0], [0, 0.33, 0], [0, 0, 0],
]


def dia10(wrist, S, C, la):
    """dia10_like (docs/reference-robots.md): FK g_0e, J^B_0i (6x6, i = 6), J^r (6x6, bidirectional)."""
    axes = ["z", "x", "x", "y", "x", "y", "z", wrist]
    tfs = [joint_tf(DIA_ORIGINS[k], axes[k], S[k], C[k]) for k in range(8)]
    tip = (IDENT, [0, 0.21, 0])
    g = tip
    for t in reversed(tfs):
        g = compose(t, g)
    jb0i = body_jacobian_cols(tfs[:6], axes[:6], (IDENT, [0, 0, 0]))
    jr = constrained_jacobian(tfs[6:], axes[6:], tip, "bi", la)
    return g, jb0i, jr


# ---------------------------------------------------------------------------------------------
# The Franka Panda from trocar's shipped URDF

PANDA_URDF = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "runtime", "model", "robots",
                          "urdf", "panda.urdf")


def snap(x):
    """0 and +-1 exactly (as Python ints, folded by the scalar helpers) when within 1e-12."""
    for v in (0, 1, -1):
        if abs(x - v) < 1e-12:
            return v
    return x


def rpy_matrix(r, p, y):
    """URDF rpy: Rot(z, y) Rot(y, p) Rot(x, r), entries snapped."""
    cr, sr, cp, sp_, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    m = [[cy * cp, cy * sp_ * sr - sy * cr, cy * sp_ * cr + sy * sr],
         [sy * cp, sy * sp_ * sr + cy * cr, sy * sp_ * cr - cy * sr],
         [-sp_, cp * sr, cp * cr]]
    return [[snap(x) for x in row] for row in m]


def panda_chain(base="panda_link0", tip="panda_link8"):
    """[(R_fixed, xyz, axis letter)] of the movable joints from base to tip, and the fixed tip
    transform (R, p) after the last movable joint (folded fixed joints)."""
    root = ET.parse(PANDA_URDF).getroot()
    by_child = {j.find("child").get("link"): j for j in root.findall("joint")}
    path = []
    link = tip
    while link != base:
        j = by_child[link]
        path.append(j)
        link = j.find("parent").get("link")
    path.reverse()
    joints, pending = [], (IDENT, [0, 0, 0])
    for j in path:
        o = j.find("origin")
        xyz = [snap(float(v)) for v in o.get("xyz", "0 0 0").split()]
        rpy = [float(v) for v in o.get("rpy", "0 0 0").split()]
        g = compose(pending, (rpy_matrix(*rpy), xyz))
        if j.get("type") == "fixed":
            pending = g
            continue
        if j.get("type") not in ("revolute", "continuous"):
            raise ValueError(j.get("type"))
        axis = [snap(float(v)) for v in j.find("axis").get("xyz").split()]
        letter = {(1, 0, 0): "x", (0, 1, 0): "y", (0, 0, 1): "z"}[tuple(axis)]
        joints.append((g[0], g[1], letter))
        pending = (IDENT, [0, 0, 0])
    return joints, pending


def panda(S, C, tip_link):
    """g_0,tip and the body Jacobian of the link `tip_link` (6x7): `panda_link8` (the flange, what
    Pinocchio is asked for) or `panda_link7` (trocar's constrained link frame F_i of panda-laparoscope,
    where panda_link8's fixed offset is folded into g_ir)."""
    joints, tip = panda_chain(tip=tip_link)
    tfs = [(matmul3(R0, rot(a, S[k], C[k])), list(xyz)) for k, (R0, xyz, a) in enumerate(joints)]
    g = tip
    for t in reversed(tfs):
        g = compose(t, g)
    return g, body_jacobian_cols(tfs, [a for _, _, a in joints], tip)


# ---------------------------------------------------------------------------------------------
# Generic robots with a computed Lambda# (bench/peers-harness/oblique7.toml, panda-link6-rcm.toml)

HARNESS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "peers-harness")


def null_free_columns(h):
    """The free columns of H's reduced row echelon form: trocar's null-space basis of H with unit
    rows is the unit vectors of those columns (H here has unit rows: no fill-in)."""
    pivots = []
    for row in h:
        nz = [k for k, x in enumerate(row) if x != 0]
        if len(nz) != 1 or row[nz[0]] != 1:
            raise ValueError(f"H row {row}: only unit rows are handled here")
        pivots.append(nz[0])
    return [k for k in range(6) if k not in pivots]


def ad_apply_translation(p, xi):
    """Ad_{(I, p)} (v, w) = (v + p x w, w)."""
    v, w = xi[:3], xi[3:]
    return [add(a, b) for a, b in zip(v, cross(p, w))] + list(w)


def rcm_outputs(tfs, axes, tip, link, h, la):
    """g_0e, J^B_0i (i = link) and J^r (computed Lambda#, g_ir = (I, (0, l_a, 0)))."""
    g = tip
    for t in reversed(tfs):
        g = compose(t, g)
    jb0i = body_jacobian_cols(tfs[:link], axes[:link], (IDENT, [0, 0, 0]))
    g_ie = tip
    for t in reversed(tfs[link:]):
        g_ie = compose(t, g_ie)
    p_ir = [0, la, 0]
    cols = []
    for k in null_free_columns(h):
        e = [1 if j == k else 0 for j in range(6)]
        cols.append(ad_inv_apply(g_ie, ad_apply_translation(p_ir, e)))
    jr = cols + body_jacobian_cols(tfs[link:], axes[link:], tip)
    return g, jb0i, jr


H_NAMED = {"x": 0, "y": 1, "z": 2, "rx": 3, "ry": 4, "rz": 5}


def h_rows(h):
    return [[1 if j == H_NAMED[r] else 0 for j in range(6)] if isinstance(r, str) else [snap(x) for x in r]
            for r in h]


def read_toml(name):
    import tomllib
    with open(os.path.join(HARNESS, name), "rb") as f:
        return tomllib.load(f)


def oblique7(S, C, la):
    d = read_toml("oblique7.toml")
    joints = d["joints"]
    axes = [[float(x) for x in j["axis"]] for j in joints]
    tfs = [(rodrigues(axes[k], S[k], C[k]), [float(x) for x in joints[k]["xyz"]]) for k in range(len(joints))]
    tip = (IDENT, [float(x) for x in d["end_effector"]["xyz"]])
    c = d["constraint"]
    assert c["xyz"] == [0, "l_a", 0], c["xyz"]
    return rcm_outputs(tfs, axes, tip, c["link"], h_rows(c["h"]), la)


def panda_rcm(S, C, la):
    d = read_toml("panda-link6-rcm.toml")
    c = d["constraint"]
    assert c["xyz"] == [0, "l_a", 0], c["xyz"]
    link = int(c["link"].removeprefix("panda_link"))
    joints, tip = panda_chain(tip=d["robot"]["tip"])
    tfs = [(matmul3(R0, rot(a, S[k], C[k])), list(xyz)) for k, (R0, xyz, a) in enumerate(joints)]
    return rcm_outputs(tfs, [a for _, _, a in joints], tip, link, h_rows(c["h"]), la)


def flatten_cols(cols):
    return [x for col in cols for x in col]  # column-major


def fk_flat(g):
    R, p = g
    return [R[i][j] for j in range(3) for i in range(3)] + list(p)  # R column-major, then p


# ---------------------------------------------------------------------------------------------
# Cases: name -> (number of joint inputs, parameter names, outputs [(name, size)])

CASES = {
    "uni": dict(nq=2, params=["l_a", "l_b", "l_8"], outs=[("jr", 42)]),
    "bzy": dict(nq=2, params=["l_a", "l_b", "l_8"], outs=[("jr", 36)]),
    "bzx": dict(nq=2, params=["l_a", "l_b", "l_8"], outs=[("jr", 36)]),
    "dia_zy": dict(nq=8, params=["l_a"], outs=[("fk", 12), ("jb0i", 36), ("jr", 36)]),
    # Panda: FK (R column-major, p) and body Jacobian (6x7) of panda_link8 / of panda_link7 (F_i).
    # l_a is not used by these outputs; it is an input like trocar's Params.
    "panda": dict(nq=7, params=["l_a"], outs=[("fk", 12), ("jb", 42)]),
    "panda_i": dict(nq=7, params=["l_a"], outs=[("fk", 12), ("jb", 42)]),
    # Generic robots with a computed Lambda#: g_0e, J^B_0i (6x6), J^r (6x5).
    "oblique7": dict(nq=7, params=["l_a"], outs=[("fk", 12), ("jb0i", 36), ("jr", 30)]),
    "panda_rcm": dict(nq=7, params=["l_a"], outs=[("fk", 12), ("jb0i", 36), ("jr", 30)]),
}


def build(case, sin, cos, qs, ps):
    S = [sin(q) for q in qs]
    C = [cos(q) for q in qs]
    if case == "dia_zy":
        g, jb, jr = dia10("y", S, C, ps[0])
        return [fk_flat(g), flatten_cols(jb), flatten_cols(jr)]
    if case in ("oblique7", "panda_rcm"):
        g, jb, jr = (oblique7 if case == "oblique7" else panda_rcm)(S, C, ps[0])
        return [fk_flat(g), flatten_cols(jb), flatten_cols(jr)]
    if case in ("panda", "panda_i"):
        g, jb = panda(S, C, "panda_link8" if case == "panda" else "panda_link7")
        return [fk_flat(g), flatten_cols(jb)]
    return [flatten_cols(preset(case, S, C, *ps))]


def as_expr_zero(x, zero):
    return zero if isinstance(x, int) and x == 0 else (x if not isinstance(x, int) else x)


# ---------------------------------------------------------------------------------------------
# CasADi

def gen_casadi(outdir, counts):
    import casadi as ca

    ops = {
        "add": ca.OP_ADD, "sub": ca.OP_SUB, "mul": ca.OP_MUL, "div": ca.OP_DIV,
        "neg": ca.OP_NEG, "sin": ca.OP_SIN, "cos": ca.OP_COS, "sq": ca.OP_SQ,
    }
    cg = {}
    for variant, opts in (("casadi", {}), ("casadi_cse", {"cse": True})):
        gen = ca.CodeGenerator(f"{variant}_peers.c", {"with_header": False, "casadi_real": "double",
                                                       "casadi_int": "long long int"})
        for case, spec in CASES.items():
            q = ca.SX.sym("q", spec["nq"])
            p = ca.SX.sym("p", len(spec["params"]))
            outs = build(case, ca.sin, ca.cos, [q[k] for k in range(spec["nq"])],
                         [p[k] for k in range(len(spec["params"]))])
            res = [ca.densify(ca.vertcat(*[ca.SX(x) if isinstance(x, (int, float)) else x for x in o]))
                   for o in outs]
            f = ca.Function(f"{variant}_{case}", [q, p], res, opts)
            gen.add(f)
            c = {k: 0 for k in ops}
            other = 0
            inv = {v: k for k, v in ops.items()}
            for k in range(f.n_instructions()):
                op = f.instruction_id(k)
                if op in inv:
                    c[inv[op]] += 1
                elif op not in (ca.OP_CONST, ca.OP_INPUT, ca.OP_OUTPUT, ca.OP_ASSIGN, ca.OP_PARAMETER):
                    other += 1
            c["other"] = other
            c["mul_add_total"] = c["add"] + c["sub"] + c["mul"] + c["div"] + c["neg"] + c["sq"]
            c["work_w"] = f.sz_w()
            counts[f"{variant}_{case}"] = c
        gen.generate(outdir + "/")
        cg[variant] = gen
    return cg


# ---------------------------------------------------------------------------------------------
# SymPy

def gen_sympy(outdir, counts):
    import sympy as sp
    from sympy.printing.c import C99CodePrinter

    printer = C99CodePrinter()
    lines = ["/* Generated by bench/peers_gen.py with SymPy %s: sympy.cse + ccode. */" % sp.__version__,
             "#include <math.h>", ""]
    for case, spec in CASES.items():
        t0 = time.time()
        qs = sp.symbols(" ".join(f"q{k}" for k in range(spec["nq"])), real=True)
        if spec["nq"] == 1:
            qs = (qs,)
        ps = sp.symbols(" ".join(spec["params"]), positive=True)
        if len(spec["params"]) == 1:
            ps = (ps,)
        outs = build(case, sp.sin, sp.cos, list(qs), list(ps))
        flat = [sp.sympify(x) for o in outs for x in o]
        repl, red = sp.cse(flat)
        # op counts of what is printed (visual count_ops over the replacements and the outputs)
        tot = sp.Integer(0)
        for _, e in repl:
            tot += sp.count_ops(e, visual=True)
        for e in red:
            tot += sp.count_ops(e, visual=True)
        c = {str(k).lower(): int(v) for k, v in (tot.as_coefficients_dict().items() if tot != 0 else [])}
        c["cse_temps"] = len(repl)
        c["mul_add_total"] = sum(v for k, v in c.items() if k in ("add", "sub", "mul", "div", "neg", "pow"))
        counts[f"sympy_{case}"] = c

        outs_args = ", ".join(f"double *{name}" for name, _ in spec["outs"])
        lines.append(f"void sympy_{case}(const double *q, const double *p, {outs_args}) {{")
        for k, s in enumerate(qs):
            lines.append(f"   const double {s} = q[{k}];")
        for k, s in enumerate(ps):
            lines.append(f"   const double {s} = p[{k}];")
        for sym, e in repl:
            lines.append(f"   const double {sym} = {printer.doprint(e)};")
        i = 0
        for name, size in spec["outs"]:
            for j in range(size):
                lines.append(f"   {name}[{j}] = {printer.doprint(red[i])};")
                i += 1
        lines.append("}")
        lines.append("")
        print(f"sympy {case}: {len(repl)} cse temporaries, {time.time() - t0:.1f} s", file=sys.stderr)
    with open(os.path.join(outdir, "sympy_peers.c"), "w") as f:
        f.write("\n".join(lines))


def write_header(outdir):
    h = ["/* Prototypes of the peers' generated C (bench/peers_gen.py). */",
         "#ifndef TROCAR_PEERS_H", "#define TROCAR_PEERS_H"]
    for case, spec in CASES.items():
        outs_args = ", ".join(f"double *{name}" for name, _ in spec["outs"])
        h.append(f"void sympy_{case}(const double *q, const double *p, {outs_args});")
    h.append("#endif")
    with open(os.path.join(outdir, "peers.h"), "w") as f:
        f.write("\n".join(h) + "\n")


def main():
    outdir = sys.argv[1] if len(sys.argv) > 1 else "out"
    os.makedirs(outdir, exist_ok=True)
    counts = {}
    gen_casadi(outdir, counts)
    gen_sympy(outdir, counts)
    write_header(outdir)
    import casadi
    import sympy
    counts["_versions"] = {"casadi": casadi.__version__, "sympy": sympy.__version__}
    with open(os.path.join(outdir, "opcounts.json"), "w") as f:
        json.dump(counts, f, indent=1, sort_keys=True)
    for k, v in sorted(counts.items()):
        print(k, v, file=sys.stderr)


if __name__ == "__main__":
    main()
