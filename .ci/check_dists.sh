#!/usr/bin/env bash
# What a packager, or a user who installs from wheels, gets: builds the sdist and the wheel of the
# core and of every plugin under plugins/ (from the sdist, as `python -m build` does), checks what
# they hold and that their package pages render (twine check), installs the wheels (not
# editable) into a fresh virtual environment outside the repository and runs mdf from a folder
# outside it on a copy of the examples; then uninstalls one
# plugin and one optional dependency and checks the rest still works and the feature that needs
# it says so in one line. Needs the package index (build requirements, dependencies); a few
# minutes, so not part of `make test` (tests/test_packaging.py checks the licence files and the
# core's sdist and wheel in seconds).
# Usage: bash .ci/check_dists.sh [WORKDIR]   (default: a temporary folder, removed at the end)
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
if [ $# -ge 1 ]; then work="$1"; mkdir -p "$work"; else
    work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT
fi
py="${PYTHON:-python3}"
say() { printf '\n== %s\n' "$*"; }

say "building from the working tree's files (tracked and untracked, not ignored) in $work"
mkdir -p "$work/src" "$work/dist" "$work/run"
(cd "$repo" && git ls-files -co --exclude-standard -z | tar --null -T - -c) | tar -x -C "$work/src"
"$py" -m venv "$work/build-env"
"$work/build-env/bin/pip" install -q build twine 2> /dev/null
for d in "$work/src" "$work"/src/plugins/*/; do
    "$work/build-env/bin/python" -m build --outdir "$work/dist" "$d" > "$work/build.log" 2>&1 ||
        { tail -20 "$work/build.log"; echo "building $d failed"; exit 1; }
done
"$py" - "$work/dist" <<'EOF'
import sys, tarfile, zipfile
from pathlib import Path
dist = Path(sys.argv[1])
bad = []
for sdist in sorted(dist.glob("*.tar.gz")):
    names = [m.name.partition("/")[2] for m in tarfile.open(sdist).getmembers()]
    bad += [f"{sdist.name}: no {n}" for n in ("LICENSE", "pyproject.toml") if n not in names]
    bad += [f"{sdist.name}: holds {n}" for n in names if n.startswith("tests/")]
for wheel in sorted(dist.glob("*.whl")):
    names = zipfile.ZipFile(wheel).namelist()
    meta = zipfile.ZipFile(wheel).read(next(n for n in names if n.endswith("/METADATA"))).decode()
    if not any(n.endswith(".dist-info/licenses/LICENSE") for n in names):
        bad.append(f"{wheel.name}: no licence file")
    if "License-Expression: MIT" not in meta or "Requires-Python: >=3.11" not in meta:
        bad.append(f"{wheel.name}: licence or Requires-Python missing from its metadata")
    if wheel.name.startswith("mdframework-") and "mdframework/py.typed" not in names:
        bad.append(f"{wheel.name}: no py.typed")
print("\n".join(bad) or f"{len(list(dist.iterdir()))} files: sdists and wheels hold what they should")
sys.exit(1 if bad else 0)
EOF

say "the package pages: each distribution's README renders as its long description"
"$work/build-env/bin/twine" check --strict "$work"/dist/* > "$work/twine.log" 2>&1 ||
    { grep -v PASSED "$work/twine.log"; echo "twine check failed"; exit 1; }
echo "$(grep -c PASSED "$work/twine.log") files pass twine check --strict"

say "installing the wheels into a fresh environment"
"$py" -m venv "$work/venv"
"$work/venv/bin/pip" install -q "$work"/dist/*.whl > "$work/pip.log" 2>&1 ||
    { tail -20 "$work/pip.log"; echo "installing the wheels failed"; exit 1; }
if grep -rqs --include='*.pth' --include='direct_url.json' "$repo" "$work/venv/lib"; then
    echo "the environment refers to the repository (an editable install?)"; exit 1
fi

say "running mdf outside the repository"
cp -r "$repo/examples" "$work/run/examples"
cd "$work/run"
export PATH="$work/venv/bin:$PATH"
mdf --version
mdf --help > /dev/null
mdf plugins | tail -3
mdf run examples/point_target.toml --out out/pt --no-figures > /dev/null
mdf run examples/cmu_walk.toml --out out/walk > /dev/null
mdf run examples/boulic_walk.toml --out out/boulic --no-figures > /dev/null
mdf dataset build examples/datasets/cmu.toml --out out/ds --set 'variations.aspect_deg=[0.0]' \
    --set 'variations.radar_range=[6.0]' 2> /dev/null
if "$py" -c "import ctypes.util, sys; sys.exit(not ctypes.util.find_library('OpenNI2'))"; then
    mdf kinect info examples/data/kinect/oni/test.oni
fi

say "one plugin uninstalled, then one optional dependency"
pip uninstall -q -y mdf-ellipsoid
mdf run examples/point_target.toml --out out/pt2 --no-figures > /dev/null
pip uninstall -q -y mujoco
set +e
err="$(mdf run examples/boulic_walk.toml --out out/boulic2 --no-figures 2>&1)"
code=$?
set -e
echo "$err"
[ "$code" = 2 ] && [ "$(echo "$err" | wc -l)" = 1 ] && [[ "$err" == *"pip install mujoco"* ]]
say "all checks passed"
