#!/usr/bin/env python3
"""Counts floating-point instructions in the peers' compiled functions (gcc -O3 -march=native).

Usage: asm_counts.py OUT [extra gcc flags]   (reads OUT/*_peers.c, writes OUT/asm_counts.json)
Counts per exported function, following calls/tail jumps into static helpers (casadi_fN):
mul (v)mulsd/pd, add (v)add/sub sd/pd, fma vf(n)madd/msub*, div (v)divsd/pd, and the libm calls made.
Packed instructions count once.
"""
import json
import os
import re
import subprocess
import sys

out = sys.argv[1]
cflags = ["-O3", "-march=native", "-c"] + sys.argv[2:]
funcs = {}
for src in ("casadi_peers.c", "casadi_cse_peers.c", "sympy_peers.c"):
    obj = os.path.join(out, src.replace(".c", ".o"))
    subprocess.run(["gcc", *cflags, os.path.join(out, src), "-o", obj], check=True)
    dis = subprocess.run(["objdump", "-d", "-r", "--no-show-raw-insn", obj], check=True,
                         capture_output=True, text=True).stdout
    cur = None
    prefix = src.replace("_peers.c", "")
    for line in dis.splitlines():
        m = re.match(r"^[0-9a-f]+ <([^>]+)>:", line)
        if m:
            cur = f"{prefix}:{m.group(1)}"
            funcs[cur] = []
            continue
        if cur and "R_X86_64_PLT32" in line:
            funcs[cur].append(("reloc", line.split()[-1].split("-")[0]))
        elif cur and "\t" in line:
            parts = line.split("\t")
            funcs[cur].append((parts[1].strip() if len(parts) > 1 else "", parts[2] if len(parts) > 2 else ""))


def count(name, seen=None):
    seen = seen or set()
    seen.add(name)
    c = {"mul": 0, "add": 0, "fma": 0, "div": 0, "calls": []}
    prefix = name.split(":")[0]
    for mnem, arg in funcs.get(name, []):
        mn = mnem.split()[0] if mnem else ""
        if mnem == "reloc":
            tgt = f"{prefix}:{arg}"
            if tgt in funcs and tgt not in seen:
                sub = count(tgt, seen)
                for k in ("mul", "add", "fma", "div"):
                    c[k] += sub[k]
                c["calls"] += sub["calls"]
            elif tgt not in funcs:
                c["calls"].append(arg)
            continue
        if re.match(r"v?mul[sp][sd]$", mn):
            c["mul"] += 1
        elif re.match(r"v?(add|sub)[sp][sd]$", mn):
            c["add"] += 1
        elif re.match(r"vfn?m(add|sub)", mn):
            c["fma"] += 1
        elif re.match(r"v?div[sp][sd]$", mn):
            c["div"] += 1
        elif mn in ("call", "jmp") and "<" in mnem + arg:
            m = re.search(r"<([^>+]+)", mnem + " " + arg)
            if m:
                tgt = f"{prefix}:{m.group(1)}"
                if tgt in funcs and tgt not in seen and tgt != name:
                    sub = count(tgt, seen)
                    for k in ("mul", "add", "fma", "div"):
                        c[k] += sub[k]
                    c["calls"] += sub["calls"]
    return c


res = {}
for case in ("uni", "bzy", "bzx", "dia_zy", "panda", "panda_i", "oblique7", "panda_rcm"):
    for impl in ("casadi", "casadi_cse", "sympy"):
        c = count(f"{impl}:{impl}_{case}")
        calls = {}
        for x in c["calls"]:
            calls[x] = calls.get(x, 0) + 1
        c["calls"] = " ".join(f"{k}x{v}" for k, v in sorted(calls.items())) or "none"
        res[f"{impl}_{case}"] = c
with open(os.path.join(out, "asm_counts.json"), "w") as f:
    json.dump(res, f, indent=1, sort_keys=True)
for k, v in sorted(res.items()):
    print(k, v)
