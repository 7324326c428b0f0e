#!/usr/bin/env bash
# DAQP's C sources for the QP peers' benchmark (bench/qp-peers): the sdist of the Python package
# `daqp` on PyPI carries them (csrc/). Downloads it into bench/out/daqp-VERSION/ (not in git).
set -euo pipefail
VERSION="${DAQP_VERSION:-0.11.0}"
here="$(cd "$(dirname "$0")" && pwd)"
out="$here/../out"
mkdir -p "$out"
if [ -d "$out/daqp-$VERSION/csrc" ]; then
    echo "DAQP $VERSION already in $out/daqp-$VERSION"
    exit 0
fi
url="$(curl -fsSL "https://pypi.org/pypi/daqp/json" | VERSION="$VERSION" python3 -c '
import json, os, sys
d = json.load(sys.stdin)
files = d["releases"].get(os.environ["VERSION"]) or sys.exit("no DAQP " + os.environ["VERSION"] + " on PyPI")
print(next(u["url"] for u in files if u["packagetype"] == "sdist"))')"
case "$url" in
    http*) ;;
    *) url="https://pypi.org/${url#../../}" ;;
esac
curl -fsSL -o "$out/daqp-$VERSION.tar.gz" "$url"
tar -xzf "$out/daqp-$VERSION.tar.gz" -C "$out"
echo "DAQP $VERSION in $out/daqp-$VERSION (MIT licence: $out/daqp-$VERSION/LICENSE)"
