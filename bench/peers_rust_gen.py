#!/usr/bin/env python3
"""The peers that emit Rust: wrenfold (``RustGenerator``, runtime traits crate ``wrenfold-traits``)
and SymForce (``codegen.Codegen`` with ``RustConfig``, nalgebra types), given the same chains as the
C peers: the expressions come from ``peers_gen.build`` (same joint transforms, same literal 0/1
folding, same outputs in the same column-major layout).

For each case of ``peers_gen.CASES`` and each tool, two functions:

* ``<case>::eval(q, p, out...)``: from the joint values (the tool's own ``sin``/``cos``);
* ``<case>::eval_trig(s, c, p, out...)``: given the sines and cosines of the joints.

Inputs are column vectors (q: nq, p: np, s and c: nq); outputs keep ``peers_gen``'s blocks: the
pose ``fk`` as the 3 x 4 matrix [R | p], every Jacobian as a 6 x n matrix (both column-major, so
the same memory as the C peers' flat blocks).

Usage: peers_rust_gen.py OUTDIR
Writes OUTDIR/wrenfold_peers.rs and OUTDIR/symforce_peers.rs (a module per case in each) and adds
the tools' versions and operation counts to OUTDIR/opcounts_rust.json.
"""

import json
import os
import re
import sys
import tempfile
import time
import typing

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peers_gen  # noqa: E402


def shape_of(name, size):
    if name == "fk":
        return 3, 4
    assert size % 6 == 0, (name, size)
    return 6, size // 6


def as_matrix(flat, rows, cols, make, zero):
    """A rows x cols matrix whose column-major storage is `flat`."""
    return make([[zero(flat[i + rows * j]) for j in range(cols)] for i in range(rows)])


def outputs(case, spec, sin, cos, qs, ps):
    blocks = peers_gen.build(case, sin, cos, qs, ps)
    return [(name, shape_of(name, size), block) for (name, size), block in zip(spec["outs"], blocks)]


# ---------------------------------------------------------------------------------------------
# wrenfold

def gen_wrenfold(outdir, counts):
    import wrenfold
    from wrenfold import code_generation as cg, sym
    from wrenfold import type_annotations as ta

    def vec(n):
        return typing.Annotated[sym.MatrixExpr, ta.Shape(rows=n, cols=1)]

    def lit(x):
        return sym.integer(x) if isinstance(x, int) else (sym.float_constant(x) if isinstance(x, float) else x)

    gen = cg.RustGenerator()
    parts = [f"// wrenfold {wrenfold.__version__}: RustGenerator, by bench/peers_rust_gen.py.", ""]
    for case, spec in peers_gen.CASES.items():
        t0 = time.time()
        nq, np_ = spec["nq"], len(spec["params"])
        fns = []
        for trig in (False, True):
            if trig:
                def f(s, c, p):
                    return [cg.OutputArg(as_matrix(b, r, k, sym.matrix, lit), name=n)
                            for n, (r, k), b in outputs(case, spec, lambda j: s[j], lambda j: c[j],
                                                        list(range(nq)), [p[j] for j in range(np_)])]
                f.__annotations__ = {"s": vec(nq), "c": vec(nq), "p": vec(np_)}
                name = "eval_trig"
            else:
                def f(q, p):
                    return [cg.OutputArg(as_matrix(b, r, k, sym.matrix, lit), name=n)
                            for n, (r, k), b in outputs(case, spec, sym.sin, sym.cos,
                                                        [q[j] for j in range(nq)],
                                                        [p[j] for j in range(np_)])]
                f.__annotations__ = {"q": vec(nq), "p": vec(np_)}
                name = "eval"
            desc = cg.create_function_description(f, name=name)
            code = gen.generate(cg.transpile(desc))
            m = re.search(r"// total: (\d+)", code)
            counts[f"wrenfold_{case}{name[4:]}"] = int(m.group(1)) if m else None
            fns.append(code)
        parts.append(f"pub mod {case} {{\n" + "\n".join(fns) + "}\n")
        print(f"wrenfold {case}: {time.time() - t0:.1f} s", file=sys.stderr)
    with open(os.path.join(outdir, "wrenfold_peers.rs"), "w") as f:
        f.write("\n".join(parts))
    return wrenfold.__version__


# ---------------------------------------------------------------------------------------------
# SymForce

def gen_symforce(outdir, counts):
    import symforce
    symforce.set_epsilon_to_symbol()
    import symforce.symbolic as sf
    from symforce import codegen
    from symforce.codegen.backends.rust import RustConfig
    from symforce.values import Values

    def lit(x):
        return sf.S(x) if isinstance(x, (int, float)) else x

    parts = [f"// SymForce {symforce.__version__}: codegen.Codegen with RustConfig, by bench/peers_rust_gen.py.", ""]
    with tempfile.TemporaryDirectory() as tmp:
        for case, spec in peers_gen.CASES.items():
            t0 = time.time()
            nq, np_ = spec["nq"], len(spec["params"])
            p = sf.Matrix(np_, 1).symbolic("p")
            fns = []
            for trig in (False, True):
                if trig:
                    s = sf.Matrix(nq, 1).symbolic("s")
                    c = sf.Matrix(nq, 1).symbolic("c")
                    outs = outputs(case, spec, lambda j: s[j], lambda j: c[j], list(range(nq)),
                                   [p[j] for j in range(np_)])
                    inputs = Values(s=s, c=c, p=p)
                    name = "eval_trig"
                else:
                    q = sf.Matrix(nq, 1).symbolic("q")
                    outs = outputs(case, spec, sf.sin, sf.cos, [q[j] for j in range(nq)],
                                   [p[j] for j in range(np_)])
                    inputs = Values(q=q, p=p)
                    name = "eval"
                out_values = Values(**{n: as_matrix(b, r, k, sf.Matrix, lit) for n, (r, k), b in outs})
                gen = codegen.Codegen(inputs=inputs, outputs=out_values, config=RustConfig(), name=name,
                                      return_key=None)
                d = gen.generate_function(output_dir=os.path.join(tmp, name), skip_directory_nesting=True)
                (path,) = d.generated_files
                code = open(path).read()
                m = re.search(r"// Total ops: (\d+)", code)
                counts[f"symforce_{case}{name[4:]}"] = int(m.group(1)) if m else None
                # The body of the template's `pub mod sym { ... }`, without its comment header.
                body = code[code.index("pub mod sym {") + len("pub mod sym {"):code.rindex("}")]
                fns.append(body)
            parts.append(f"pub mod {case} {{\n" + "\n".join(fns) + "}\n")
            print(f"symforce {case}: {time.time() - t0:.1f} s", file=sys.stderr)
    with open(os.path.join(outdir, "symforce_peers.rs"), "w") as f:
        f.write("\n".join(parts))
    return symforce.__version__


def main():
    outdir = sys.argv[1] if len(sys.argv) > 1 else "out"
    os.makedirs(outdir, exist_ok=True)
    counts = {}
    versions = {"wrenfold": gen_wrenfold(outdir, counts), "symforce": gen_symforce(outdir, counts)}
    counts["_versions"] = versions
    with open(os.path.join(outdir, "opcounts_rust.json"), "w") as f:
        json.dump(counts, f, indent=1, sort_keys=True)
    print(json.dumps(counts), file=sys.stderr)


if __name__ == "__main__":
    main()
