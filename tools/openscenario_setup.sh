#!/usr/bin/env bash
# Create (or reuse) the Python venv with the OpenSCENARIO XML / OpenDRIVE checking
# tools used by tools/openscenario_check.py, and make sure SUMO's netconvert exists.
#
#   tools/openscenario_setup.sh [VENV_DIR]      default VENV_DIR: .venv-xosc (relative to the cwd)
#
# Installs (pinned) into VENV_DIR:
#   asam-qc-openscenarioxml  ASAM checker bundle "xoscBundle" (CLI: qc_openscenario -c CONFIG.xml)
#   asam-qc-opendrive        ASAM checker bundle "xodrBundle" (CLI: qc_opendrive -c CONFIG.xml)
#   asam-qc-baselib          Configuration/Result (.xqar) models both bundles are built on
#   scenariogeneration       pyoscx reader/writer, used for the .xosc read-back
# asam-qc-framework is NOT installed: it only orchestrates several bundles and renders
# reports; each bundle runs standalone from a config file and writes its own .xqar.
# Every transitive dependency is pinned too, so CI gets the same tree every time.
#
# If `netconvert` is not on PATH, Debian's `sumo` package is apt-installed (as root, or
# through sudo when not root).
#
# Idempotent: nothing is installed when the venv already has the pinned versions and
# netconvert exists. Progress goes to stderr; the last (only) stdout line is the venv's
# python path, so callers can do:   PY=$(bash tools/openscenario_setup.sh .venv-xosc)
#
# Environment:
#   PYTHON   interpreter used to create the venv (default: python3; needs >= 3.11,
#            scenariogeneration 0.16.7 requires it)
#
# Cost on a fresh machine (2 cores): ~20 s for the venv (~300 MB: scipy, numpy, lxml,
# pydantic, xmlschema), ~15 s for apt (sumo 1.15.0 on Debian 12, 41 packages).
set -euo pipefail

venv=${1:-.venv-xosc}
python=${PYTHON:-python3}

# direct requirements first, then the transitive pins (pip resolves them together)
PINS=(
    asam-qc-openscenarioxml==1.0.0
    asam-qc-opendrive==1.0.0
    asam-qc-baselib==1.1.0
    scenariogeneration==0.16.7
    annotated-types==0.8.0
    elementpath==4.8.0
    lxml==5.4.0
    numpy==1.26.4
    pybind11==3.1.0
    pyclothoids==0.1.5
    pydantic==2.14.4
    pydantic-core==2.50.5
    pydantic-xml==2.22.0
    scipy==1.17.1
    semver==3.1.2
    transforms3d==0.4.2
    typing-extensions==4.16.0
    typing-inspection==0.4.5
    xmlschema==3.4.5
)

log() { echo "openscenario_setup.sh: $*" >&2; }

# run "$@" with its output in a log that is shown (on stderr) only when it fails
quiet() {
    local out
    out=$(mktemp)
    if "$@" >"$out" 2>&1; then
        rm -f "$out"
    else
        local rc=$?
        log "command failed ($rc): $*"
        cat "$out" >&2
        rm -f "$out"
        return "$rc"
    fi
}

as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

have_pins() {
    [ -x "$venv/bin/python" ] &&
        "$venv/bin/python" - "${PINS[@]}" >/dev/null 2>&1 <<'EOF'
import sys
from importlib.metadata import version, PackageNotFoundError
for pin in sys.argv[1:]:
    name, want = pin.split("==")
    try:
        if version(name) != want:
            sys.exit(1)
    except PackageNotFoundError:
        sys.exit(1)
import qc_openscenario.main, qc_opendrive.main, qc_baselib, scenariogeneration.xosc  # noqa
EOF
}

# --- Python venv -------------------------------------------------------------
if have_pins; then
    log "$venv already has the pinned checker packages"
else
    if [ ! -x "$venv/bin/python" ]; then
        log "creating venv $venv with $python"
        quiet "$python" -m venv "$venv"
    fi
    log "installing ${PINS[*]:0:4} (+ pinned dependencies) into $venv"
    quiet "$venv/bin/python" -m pip install --disable-pip-version-check --no-input \
        --quiet "${PINS[@]}"
    if ! have_pins; then
        log "the pinned packages are not importable from $venv after install"
        exit 1
    fi
fi

# --- netconvert (Debian package sumo) ----------------------------------------
if command -v netconvert >/dev/null 2>&1; then
    log "netconvert found: $(command -v netconvert)"
else
    log "netconvert not on PATH: apt-installing Debian's sumo"
    quiet as_root env DEBIAN_FRONTEND=noninteractive apt-get update -q
    quiet as_root env DEBIAN_FRONTEND=noninteractive \
        apt-get install -y -q --no-install-recommends sumo
    if ! command -v netconvert >/dev/null 2>&1; then
        log "netconvert still not on PATH after installing sumo"
        exit 1
    fi
fi

# absolute path of the venv's python (do not resolve the symlink: it must stay inside the venv)
echo "$(cd "$venv/bin" && pwd)/python"
