#!/usr/bin/env bash
# Set up the Radiance cross-check: a venv at the repository root (.venv-radiance/) with the
# pinned pyradiance wheel, which carries Radiance's binaries, and numpy. Idempotent: a second
# run only checks that the binaries start.
#
#   scripts/radiance/setup.sh            # set up (or check)
#   source scripts/radiance/env.sh       # optional: Radiance's bin on PATH, RAYPATH set
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
venv="$root/.venv-radiance"
req="$here/requirements.txt"
stamp="$venv/.requirements.sha256"

want="$(sha256sum "$req" | cut -d' ' -f1)"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$req"
    echo "$want" > "$stamp"
fi

pkg="$("$venv/bin/python" -c 'import os, pyradiance; print(os.path.dirname(pyradiance.__file__))')"
for tool in obj2rad oconv rtrace rpict gensky; do
    [ -x "$pkg/bin/$tool" ] || { echo "setup.sh: $pkg/bin/$tool missing" >&2; exit 1; }
done
export PATH="$pkg/bin:$PATH" RAYPATH="$pkg/lib"
version="$(rtrace -version 2>&1 | head -1)"
echo "Radiance ready: $version"
echo "  bin: $pkg/bin"
echo "  RAYPATH=$pkg/lib"
echo "  python: $venv/bin/python"
