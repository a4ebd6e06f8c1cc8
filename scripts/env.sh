# Sourced by run-main and run-tests: installs what dyadfmu needs on a Debian
# machine (system packages where root, a Python venv in .venv) and builds.
# Variables: DYADFMU_ROOT (the checkout), DYADFMU_VENV (default $DYADFMU_ROOT/.venv).

DYADFMU_ROOT=${DYADFMU_ROOT:-$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)}
DYADFMU_VENV=${DYADFMU_VENV:-$DYADFMU_ROOT/.venv}

dyadfmu_log() { printf '== %s\n' "$*" >&2; }

# Debian packages: command to check -> package providing it.
dyadfmu_ensure_system() {
    local missing=()
    command -v cmake >/dev/null 2>&1 || missing+=(cmake)
    command -v cc >/dev/null 2>&1 || missing+=(gcc libc6-dev)
    command -v make >/dev/null 2>&1 || missing+=(make)
    command -v python3 >/dev/null 2>&1 || missing+=(python3)
    if ! python3 -c 'import venv, ensurepip' >/dev/null 2>&1; then
        missing+=(python3-venv)
    fi
    # GSL for the generic-solve baseline of the study; valgrind counts its instructions.
    [ -f /usr/include/gsl/gsl_linalg.h ] || missing+=(libgsl-dev)
    command -v valgrind >/dev/null 2>&1 || missing+=(valgrind)
    if [ ${#missing[@]} -eq 0 ]; then
        return 0
    fi
    if [ "$(id -u)" -ne 0 ]; then
        dyadfmu_log "missing system packages: ${missing[*]} (run as root, or install them: apt-get install ${missing[*]})"
        return 1
    fi
    dyadfmu_log "installing system packages: ${missing[*]}"
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
}

dyadfmu_ensure_venv() {
    local stamp="$DYADFMU_VENV/.dyadfmu-installed"
    if [ ! -x "$DYADFMU_VENV/bin/python" ]; then
        dyadfmu_log "creating Python venv in $DYADFMU_VENV"
        python3 -m venv "$DYADFMU_VENV"
    fi
    if [ ! -f "$stamp" ] || [ "$DYADFMU_ROOT/scripts/pyproject.toml" -nt "$stamp" ]; then
        dyadfmu_log "installing the pinned Python dependencies (scripts/pyproject.toml)"
        "$DYADFMU_VENV/bin/python" -m pip install -q --upgrade pip >/dev/null
        "$DYADFMU_VENV/bin/python" -m pip install -q -e "$DYADFMU_ROOT/scripts[test]"
        touch "$stamp"
    fi
}

# dyadfmu_build DIR [cmake options...]: configure and build into DIR, the FMUs
# with the venv's Python (its fmpy supplies the FMI headers).
dyadfmu_build() {
    local dir=$1
    shift
    dyadfmu_log "building in $dir $*"
    cmake -S "$DYADFMU_ROOT" -B "$dir" -DCMAKE_BUILD_TYPE=Release \
        -DPython3_EXECUTABLE="$DYADFMU_VENV/bin/python" "$@" >/dev/null
    cmake --build "$dir" -j "$(nproc 2>/dev/null || echo 2)" >/dev/null
}
