#!/usr/bin/env python3
"""Collects bench/peers.sh's measurements into one Markdown table.

Inputs (all optional, missing cells print as "-"):
  CRITERION_DIR/<case>/<impl>/new/estimates.json   criterion medians (ns/eval)
  OUT/callgrind.json                              {"impl/case": instructions per eval}
  OUT/cputime.json                                {"impl/case": thread CPU time ns per eval}
  OUT/opcounts.json                               source-level op counts from peers_gen.py
  OUT/asm_counts.json                             FP instructions in the compiled functions
  DEFAULT_ISA_CRITERION_DIR, OUT/cputime_default_isa.json   the Panda's default-ISA run
Usage: peers_table.py OUT CRITERION_DIR [DEFAULT_ISA_CRITERION_DIR]
  OUT/callgrind_default_isa.json                  instructions at the default x86-64 ISA
Writes OUT/table.md (every case), OUT/rust_peers.md (trocar vs wrenfold and SymForce), OUT/ratios.md (trocar's generated f64 over each peer: criterion,
CPU time, callgrind) and OUT/panda.md (the Panda: trocar vs Pinocchio).
"""

import json
import os
import sys

CASES = [("uni", "J^r unidirectional 6x7"), ("bzy", "J^r bidirectional-zy 6x6"),
         ("bzx", "J^r bidirectional-zx 6x6"), ("dia_zy", "dia10_like zy: FK + J^B_0i + J^r"),
         ("panda", "Panda panda_link8: pose + J^B 6x7"),
         ("panda_i", "Panda F_i = panda_link7: g_0i + J^B_0i 6x7"),
         ("oblique7", "oblique7 (7 oblique float axes, RCM on link 6, 2 explicit H rows): FK + J^B_0i + J^r"),
         ("panda_rcm", "Panda, RCM on panda_link6 (H = x, z): FK + J^B_0i + J^r")]
# Cases of the ratio table (ours / each peer); the Panda's pose + Jacobian cases are in panda.md.
RATIO_CASES = ["uni", "bzy", "bzx", "dia_zy", "oblique7", "panda_rcm"]
PANDA = [c for c in CASES if c[0] in ("panda", "panda_i")]
IMPLS = [("casadi", "CasADi C (SX, defaults)"), ("casadi_cse", "CasADi C (SX, cse=True)"),
         ("sympy", "SymPy C (cse + ccode)"), ("numeric", "trocar numeric runtime (Chain + Constraint, f64)"),
         ("rust_reference", "harness f64 reference (Vec-based loops)"),
         ("baseline", "trocar generated f64 of 2026-11-23 (frozen baseline, presets)"),
         ("ours_f64", "trocar generated f64"), ("ours_f64_given_trig", "trocar generated f64, given JointTrig (no trig)"),
         ("ours_f32", "trocar generated f32"),
         ("wrenfold", "wrenfold 0.5 Rust (RustGenerator), from q"),
         ("wrenfold_given_trig", "wrenfold 0.5 Rust, given the sines and cosines"),
         ("symforce", "SymForce 0.12 Rust (RustConfig, nalgebra), from q"),
         ("symforce_given_trig", "SymForce 0.12 Rust, given the sines and cosines"),
         ("pinocchio", "Pinocchio C++ computeFrameJacobian(LOCAL), pose from it (g++ -O3, default ISA)"),
         ("pinocchio_fk", "Pinocchio C++ forwardKinematics + updateFramePlacement + computeFrameJacobian (default ISA)"),
         ("ours_trig", "floor: trocar JointTrig::new alone (7 joints)"),
         ("trig_c_glibc", "floor: C glibc sin + cos of the 7 joints")]
TRIG = [("c_glibc_two_sincos", "trig_c_glibc", "C glibc sin+cos of 2 joints (gcc merges into sincos)"),
        ("rust_std_two_sin_cos_f64", "trig_std_f64", "Rust std f64::sin_cos x2"),
        ("trocar_real_two_sin_cos_f64", None, "trocar::Real::sin_cos f64 x2 (std build)"),
        (None, "trig_fast_f64", "trocar::emitted::fast::sin_cos_f64 x2 (no_std path)"),
        ("libm_two_sin_cos_f64", "trig_libm_f64", "libm crate sin, cos f64 x2 (previous no_std path)"),
        ("rust_std_two_sin_cos_f32", "trig_std_f32", "Rust std f32::sin_cos x2"),
        ("trocar_real_two_sin_cos_f32", None, "trocar::Real::sin_cos f32 x2 (std build)"),
        (None, "trig_fast_f32", "trocar::emitted::fast::sin_cos_f32 x2 (no_std path)"),
        ("libm_two_sin_cos_f32", "trig_libm_f32", "libm crate sinf, cosf x2 (previous no_std path)"),
        ("fast_two_sin_cos_f64", None, "trocar::emitted::fast::sin_cos_f64 x2 (criterion)"),
        ("fast_two_sin_cos_f32", None, "trocar::emitted::fast::sin_cos_f32 x2 (criterion)")]


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def median(crit, group, name):
    est = load(os.path.join(crit, group, name, "new", "estimates.json"))
    if not est:
        return None
    return est["median"]["point_estimate"]


def fmt(x, nd=1):
    if x is None:
        return "-"
    if isinstance(x, float):
        return f"{x:.{nd}f}"
    return str(x)


def main():
    out, crit = sys.argv[1], sys.argv[2]
    cg = load(os.path.join(out, "callgrind.json"))
    ops = load(os.path.join(out, "opcounts.json"))
    asm = load(os.path.join(out, "asm_counts.json"))
    cpu = load(os.path.join(out, "cputime.json"))
    noop = cg.get("noop/-")

    def net(ins, case):
        """Instructions net of the driver loop (the Panda's loop also cycles its 16 configurations)."""
        base = cg.get(f"noop/{case}", noop) if case.startswith("panda") else noop
        return ins - base if ins is not None and base is not None else ins

    lines = []
    lines.append("| function | implementation | ns/eval CPU time (median) | ns/eval criterion (median) | instr/eval (callgrind) | source ops: mul / add+sub / div / neg / sin+cos | x86 FP instr: mul / add+sub / fma / div, calls |")
    lines.append("|---|---|---:|---:|---:|---|---|")
    for case, cdesc in CASES:
        for impl, idesc in IMPLS:
            t = median(crit, case, impl)
            ins = cg.get(f"{impl}/{case}")
            if t is None and ins is None:
                continue
            ins = net(ins, case)
            ct = cpu.get(f"{impl}/{case}")
            o = ops.get(f"{impl}_{case}")
            if o:
                adds = o.get("add", 0) + o.get("sub", 0)
                muls = o.get("mul", 0) + o.get("pow", 0) + o.get("sq", 0)
                src = f"{muls} / {adds} / {o.get('div', 0)} / {o.get('neg', 0)} / {o.get('sin', 0) + o.get('cos', 0)}"
            else:
                src = "-"
            a = asm.get(f"{impl}_{case}")
            if a:
                mach = f"{a['mul']} / {a['add']} / {a['fma']} / {a['div']}, {a['calls']}"
            else:
                mach = "-"
            lines.append(f"| {cdesc} | {idesc} | {fmt(ct)} | {fmt(t)} | {fmt(ins, 0)} | {src} | {mach} |")
    lines.append("")
    lines.append("| trigonometry (two joints, arguments 0.5 and 0.3) | ns CPU time (median) | ns criterion (median) | instr (callgrind) |")
    lines.append("|---|---:|---:|---:|")
    for bench, cgname, desc in TRIG:
        t = median(crit, "trig", bench) if bench else None
        ins = cg.get(f"{cgname}/-") if cgname else None
        if ins is not None and noop is not None:
            ins = ins - noop
        ct = cpu.get(f"{cgname}/-") if cgname else None
        if t is None and ins is None:
            continue
        lines.append(f"| {desc} | {fmt(ct)} | {fmt(t)} | {fmt(ins, 0)} |")
    if noop is not None:
        lines.append("")
        lines.append(f"Instruction counts are net of the driver loop ({noop:.0f} instructions per iteration, measured with `cg_driver noop`).")
    ratios = ratio_table(crit, cg, cpu, net)
    with open(os.path.join(out, "ratios.md"), "w") as f:
        f.write(ratios)
    lines += ["", ratios]
    panda = panda_table(out, crit, sys.argv[3] if len(sys.argv) > 3 else None, cg, cpu, net)
    text = "\n".join(lines) + "\n"
    if panda:
        text += "\n" + panda
        with open(os.path.join(out, "panda.md"), "w") as f:
            f.write(panda)
    rust = rust_peers_table(out, crit, sys.argv[3] if len(sys.argv) > 3 else None, cg, cpu)
    if rust:
        text += "\n" + rust
        with open(os.path.join(out, "rust_peers.md"), "w") as f:
            f.write(rust)
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write(text)
    print(text)


def ratio_table(crit, cg, cpu, net):
    """ours_f64 over casadi, casadi_cse, sympy and (presets) the frozen baseline: criterion median, thread CPU time, callgrind."""
    lines = ["| case | vs | criterion ours / peer (ns) | CPU time ours / peer (ns) | instructions ours / peer |",
             "|---|---|---:|---:|---:|"]

    def r(a, b, nd=1):
        if a is None or b is None or b == 0:
            return "-"
        return f"{a:.{nd}f} / {b:.{nd}f} = **{a / b:.2f}×**"
    for case in RATIO_CASES:
        t_o = median(crit, case, "ours_f64")
        c_o = cpu.get(f"ours_f64/{case}")
        i_o = net(cg.get(f"ours_f64/{case}"), case)
        for peer in ("casadi", "casadi_cse", "sympy", "baseline"):
            if median(crit, case, peer) is None and cg.get(f"{peer}/{case}") is None:
                continue
            lines.append(f"| {case} | {peer} | {r(t_o, median(crit, case, peer))} | "
                         f"{r(c_o, cpu.get(f'{peer}/{case}'))} | "
                         f"{r(i_o, net(cg.get(f'{peer}/{case}'), case), 0)} |")
    return "\n".join(lines) + "\n"


PANDA_IMPLS = [
    ("pinocchio", "Pinocchio C++ `computeFrameJacobian(.., LOCAL, J)`; pose = `data.iMf[0]`, left by it"),
    ("pinocchio_fk", "Pinocchio C++ `forwardKinematics` + `updateFramePlacement` + `computeFrameJacobian`"),
    ("ours_f64", "trocar generated f64: `JointTrig::new` (7 `sin_cos`) + pose + Jacobian `_trig`"),
    ("ours_f64_given_trig", "trocar generated f64, given `JointTrig` (no trig)"),
    ("ours_f32", "trocar generated f32"),
    ("casadi", "CasADi C (SX, defaults)"),
    ("casadi_cse", "CasADi C (SX, cse=True)"),
    ("sympy", "SymPy C (cse + ccode)"),
    ("numeric", "trocar numeric runtime (`Chain::link_frame` + `partial_body_jacobian`, f64)"),
    ("rust_reference", "harness f64 reference (Vec-based loops)"),
    ("ours_trig", "floor: trocar `JointTrig::new` alone (`sin_cos_array` of the 7 joints)"),
    ("trig_c_glibc", "floor: C glibc `sin` + `cos` of the 7 joints (gcc merges into `sincos`)"),
]


def panda_table(out, crit, crit_default, cg, cpu, net):
    """The Panda: every implementation in the native-Rust run and in the default-ISA run, and the
    ratios of trocar's generated code to Pinocchio's computeFrameJacobian."""
    cpu_d = load(os.path.join(out, "cputime_default_isa.json"))
    rows = []
    for case, cdesc in PANDA:
        for impl, idesc in PANDA_IMPLS:
            t = median(crit, case, impl)
            td = median(crit_default, case, impl) if crit_default else None
            ins = net(cg.get(f"{impl}/{case}"), case)
            if t is None and td is None and ins is None:
                continue
            rows.append(f"| {cdesc} | {idesc} | {fmt(t)} | {fmt(cpu.get(f'{impl}/{case}'))} | "
                        f"{fmt(td)} | {fmt(cpu_d.get(f'{impl}/{case}'))} | {fmt(ins, 0)} |")
    if not rows:
        return ""
    lines = ["| frame: output | implementation | ns criterion, Rust native | ns CPU time, Rust native | "
             "ns criterion, all default ISA | ns CPU time, all default ISA | instr/eval (callgrind) |",
             "|---|---|---:|---:|---:|---:|---:|"] + rows
    ratios = []
    for case, cdesc in PANDA:
        for label, c, cp in (("Rust native", crit, cpu), ("all default ISA", crit_default, cpu_d)):
            if not c:
                continue
            pin = median(c, case, "pinocchio")
            for impl in ("ours_f64", "ours_f64_given_trig", "sympy", "casadi"):
                t = median(c, case, impl)
                if pin and t:
                    ratios.append(f"| {cdesc} | {label} | {impl} | {t:.1f} / {pin:.1f} = **{t / pin:.2f}×** |")
    if ratios:
        lines += ["", "| frame: output | run | implementation | criterion median / Pinocchio `computeFrameJacobian` |",
                  "|---|---|---|---|"] + ratios
    lines += ["", "Pinocchio is always g++ -O3 at the default x86-64 ISA (the wheel's libpinocchio is; see "
              "build.rs). \"Rust native\": our Rust at `-C target-cpu=native`, the peers' C at "
              "`-march=native`; \"all default ISA\": Rust `-C target-cpu=x86-64`, C `-march=x86-64`. "
              "Every Panda implementation cycles through the same 16 configurations. Instruction counts "
              "(native build without AVX-512) are net of the Panda driver loop (`cg_driver noop panda`)."]
    return "\n".join(lines) + "\n"


RUST_ROWS = [
    ("ours_f64", "trocar (one function: `constrained_jacobian` for the presets, the fused `pose_and_jacobian` / "
                 "`link_pose_and_jacobian` for the Panda, the fused `step_outputs` for dia10_like, oblique7 and the "
                 "Panda RCM)"),
    ("wrenfold", "wrenfold (one function)"),
    ("symforce", "SymForce (one function)"),
    ("ours_f64_given_trig", "trocar, given the sines and cosines"),
    ("wrenfold_given_trig", "wrenfold, given the sines and cosines"),
    ("symforce_given_trig", "SymForce, given the sines and cosines"),
    ("wrenfold_fed_trocar_sin_cos", "wrenfold `eval_trig` fed trocar's `JointTrig::new` in the loop"),
    ("symforce_fed_trocar_sin_cos", "SymForce `eval_trig` fed trocar's `JointTrig::new` in the loop"),
]


def rust_peers_table(out, crit, crit_default, cg, cpu):
    """trocar's generated f64 against wrenfold's and SymForce's Rust: instructions (default ISA,
    native without AVX-512), thread CPU time and criterion medians (native, default ISA), then
    trocar over the faster of the two, from q and given the sines and cosines."""
    cgd = load(os.path.join(out, "callgrind_default_isa.json"))
    cpu_d = load(os.path.join(out, "cputime_default_isa.json"))

    def net(table, impl, case):
        v = table.get(f"{impl}/{case}")
        base = table.get(f"noop/{case}") if case.startswith("panda_") or case == "panda" else None
        base = base if base is not None else table.get("noop/-")
        return v - base if v is not None and base is not None else v

    def metrics(impl, case):
        return [net(cgd, impl, case), net(cg, impl, case), cpu_d.get(f"{impl}/{case}"), cpu.get(f"{impl}/{case}"),
                median(crit_default, case, impl) if crit_default else None, median(crit, case, impl)]
    heads = ["instr, default ISA", "instr, native (no AVX-512)", "ns CPU, default ISA", "ns CPU, native",
             "ns criterion, default ISA", "ns criterion, native"]
    lines = ["| case | implementation | " + " | ".join(heads) + " |", "|---|---|" + "---:|" * len(heads)]
    ratio = ["| case | trocar / faster peer | " + " | ".join(heads) + " |", "|---|---|" + "---:|" * len(heads)]
    any_row = False
    for case, cdesc in CASES:
        m = {impl: metrics(impl, case) for impl, _ in RUST_ROWS}
        if all(v is None for vs in m.values() for v in vs):
            continue
        any_row = True
        for impl, desc in RUST_ROWS:
            if all(v is None for v in m[impl]):
                continue
            nd = [0, 0, 1, 1, 1, 1]
            lines.append(f"| {cdesc} | {desc} | " + " | ".join(fmt(v, d) for v, d in zip(m[impl], nd)) + " |")
        for ours, peers, label in (("ours_f64", ("wrenfold", "symforce"), "from q"),
                                   ("ours_f64_given_trig", ("wrenfold_given_trig", "symforce_given_trig"),
                                    "given sin, cos")):
            cells = []
            for k in range(len(heads)):
                o = m[ours][k]
                ps = [m[p][k] for p in peers if m[p][k] is not None]
                cells.append(f"{o / min(ps):.2f}×" if o is not None and ps and min(ps) > 0 else "-")
            ratio.append(f"| {case} | {label} | " + " | ".join(cells) + " |")
    if not any_row:
        return ""
    return "\n".join(lines + ["", "Instruction counts are net of the driver loop (`cg_driver noop`).", ""] + ratio) + "\n"


if __name__ == "__main__":
    main()
