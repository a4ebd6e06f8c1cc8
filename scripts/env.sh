# Sourced by run-main and run-tests: installs what dyadfmu needs on a Debian
# machine (system packages where root, a Python venv in .venv) and builds.
# Variables: DYADFMU_ROOT (the checkout), DYADFMU_VENV (default $DYADFMU_ROOT/.venv).

DYADFMU_ROOT=${DYADFMU_ROOT:-$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)}
DYADFMU_VENV=${DYADFMU_VENV:-$DYADFMU_ROOT/.venv}

dyadfmu_log() { printf '== %s\n' "$*" >&2; }

# dyadfmu_wants_help ARGS...: true if -h or --help is among the arguments.
dyadfmu_wants_help() {
    local arg
    for arg in "$@"; do
        case $arg in -h | --help) return 0 ;; esac
    done
    return 1
}

# dyadfmu_check_args COMMAND ARGS...: the arguments of 'dyadfmu COMMAND' checked by its own
# parser with nothing run (dyadfmu --parse-only; needs the venv), so that a wrapper stops on
# a mistyped option before it builds: exits with the parser's message and status (2).
dyadfmu_check_args() {
    "$DYADFMU_VENV/bin/dyadfmu" --parse-only "$@" || exit $?
}

# dyadfmu_ensure_system [NEED...]: the Debian packages a command needs. Always the
# compiler, make, CMake, pkg-config (scripts/tests/test_install.py) and Python with
# venv; NEED `study`: GSL (the generic-solve baseline of the benchmark) and valgrind
# (its instruction counts); `windows`: the MinGW-w64 cross compiler and Wine (the
# FMUs' Windows binaries, tested under Wine).
# As root the missing ones are installed; otherwise the command stops, naming them
# and itself.
dyadfmu_ensure_system() {
    local missing=() need
    command -v cmake >/dev/null 2>&1 || missing+=(cmake)
    command -v cc >/dev/null 2>&1 || missing+=(gcc libc6-dev)
    command -v make >/dev/null 2>&1 || missing+=(make)
    command -v pkg-config >/dev/null 2>&1 || missing+=(pkg-config)
    command -v python3 >/dev/null 2>&1 || missing+=(python3)
    if ! python3 -c 'import venv, ensurepip' >/dev/null 2>&1; then
        missing+=(python3-venv)
    fi
    for need in "$@"; do
        case $need in
        study)
            [ -f /usr/include/gsl/gsl_linalg.h ] || missing+=(libgsl-dev)
            command -v valgrind >/dev/null 2>&1 || missing+=(valgrind)
            ;;
        windows)
            command -v x86_64-w64-mingw32-gcc >/dev/null 2>&1 || missing+=(gcc-mingw-w64-x86-64)
            command -v wine >/dev/null 2>&1 || missing+=(wine wine64)
            ;;
        *)
            dyadfmu_log "dyadfmu_ensure_system: unknown need '$need' (study, windows)"
            return 2
            ;;
        esac
    done
    if [ ${#missing[@]} -eq 0 ]; then
        return 0
    fi
    if [ "$(id -u)" -ne 0 ]; then
        dyadfmu_log "$(basename "$0") needs the system packages ${missing[*]}: install them (apt-get install ${missing[*]}) or run it as root"
        return 1
    fi
    dyadfmu_log "installing system packages for $(basename "$0"): ${missing[*]}"
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
}

dyadfmu_ensure_venv() {
    local stamp="$DYADFMU_VENV/.dyadfmu-installed"
    if [ ! -x "$DYADFMU_VENV/bin/python" ]; then
        dyadfmu_log "creating Python venv in $DYADFMU_VENV"
        python3 -m venv "$DYADFMU_VENV"
    fi
    if [ ! -f "$stamp" ] || [ "$DYADFMU_ROOT/scripts/pyproject.toml" -nt "$stamp" ] ||
        [ "$DYADFMU_ROOT/scripts/constraints.txt" -nt "$stamp" ]; then
        # The exact versions of scripts/constraints.txt within pyproject.toml's ranges. The
        # package is installed editable without its CMake build (wheel.cmake=false): here the
        # core and the FMUs come from the checkout's build directories.
        dyadfmu_log "installing the pinned Python dependencies (scripts/constraints.txt)"
        "$DYADFMU_VENV/bin/python" -m pip install -q --upgrade pip >/dev/null
        "$DYADFMU_VENV/bin/python" -m pip install -q -c "$DYADFMU_ROOT/scripts/constraints.txt" \
            -C wheel.cmake=false -e "$DYADFMU_ROOT/scripts[test]"
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

# ---- probes of the FMU binaries (tests/fmu_fuzz.c, fmu_api_tests.c, fmu_threads.c) ----
# The FMUs the ThreadSanitizer build makes: one of each kind (a generic dyad, a
# tailored multi-dyad scene, the drive), enough for the thread test and no more.
DYADFMU_TSAN_FMUS=${DYADFMU_TSAN_FMUS:-"dyad_rrt;sixbar;drive"}

# dyadfmu_build_tsan DIR: the thread test and the FMUs of DYADFMU_TSAN_FMUS,
# all built with -fsanitize=thread; nothing else of the project.
dyadfmu_build_tsan() {
    local dir=$1 targets=(fmu_threads) id
    dyadfmu_log "building in $dir (ThreadSanitizer: $DYADFMU_TSAN_FMUS)"
    cmake -S "$DYADFMU_ROOT" -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDYADFMU_TSAN=ON \
        -DDYADFMU_BUILD_BENCH=OFF -DDYADFMU_PROBE_FMUS="$DYADFMU_TSAN_FMUS" \
        -DPython3_EXECUTABLE="$DYADFMU_VENV/bin/python" >/dev/null
    for id in ${DYADFMU_TSAN_FMUS//;/ }; do
        targets+=("${id}_fmi2_package" "${id}_fmi3_package")
    done
    cmake --build "$dir" -j "$(nproc 2>/dev/null || echo 2)" --target "${targets[@]}" >/dev/null
}
# ---- end of the probes' block ----

# ---- the second FMI importer (scripts/tests/test_importers.py) ----------------------
# fmi-sim, a Rust FMI 2 / FMI 3 importer independent of fmpy, at the version
# scripts/dyadfmu/cosim/importers.py pins (FMI_SIM_VERSION). `cargo install` builds it once into
# the cargo install root (~/.cargo/bin unless CARGO_INSTALL_ROOT or CARGO_HOME say
# otherwise; about 12 CPU minutes); a later run finds the pinned version there and skips.
# The build needs cargo (PATH or ~/.cargo/bin, else Debian's cargo-web, since bookworm's
# cargo / rustc 1.63 is older than fmi-sim's dependencies allow) and libclang (Debian's
# libclang-dev). Exports DYADFMU_FMI_SIM for the tests. fmutool comes with the venv
# (scripts/pyproject.toml, test extras). Where fmi-sim cannot be installed, the tests
# skip it, except under CI (CI=true), where this returns non-zero.
dyadfmu_fmi_sim_pin() {
    sed -n 's/^FMI_SIM_VERSION = "\([0-9.]*\)"$/\1/p' "$DYADFMU_ROOT/scripts/dyadfmu/cosim/importers.py"
}

dyadfmu_fmi_sim_installed() {   # the version of the fmi-sim at $1, or nothing
    [ -x "$1" ] || return 0
    RUST_BACKTRACE=0 "$1" --version 2>&1 | sed -n 's/.*fmi-sim \([0-9][0-9.]*\).*/\1/p' | head -n 1
}

dyadfmu_ensure_fmi_sim() {
    local want root bin cargo missing=()
    want=$(dyadfmu_fmi_sim_pin)
    root=${CARGO_INSTALL_ROOT:-${CARGO_HOME:-$HOME/.cargo}}
    bin="$root/bin/fmi-sim"
    if [ -n "$want" ] && [ "$(dyadfmu_fmi_sim_installed "$bin")" = "$want" ]; then
        export DYADFMU_FMI_SIM="$bin"
        return 0
    fi
    cargo=$(command -v cargo 2>/dev/null || true)
    if [ -z "$cargo" ] && [ -x "${CARGO_HOME:-$HOME/.cargo}/bin/cargo" ]; then
        cargo="${CARGO_HOME:-$HOME/.cargo}/bin/cargo"
    fi
    [ -n "$cargo" ] || missing+=(cargo-web)
    dpkg-query -W -f='${Status}' libclang-dev 2>/dev/null | grep -q 'ok installed' \
        || missing+=(libclang-dev)
    if [ ${#missing[@]} -gt 0 ]; then
        if [ "$(id -u)" -ne 0 ]; then
            dyadfmu_log "fmi-sim $want not installed: it needs ${missing[*]} (run as root, or apt-get install ${missing[*]})"
            [ "${CI:-}" != "true" ]
            return
        fi
        dyadfmu_log "installing system packages for fmi-sim: ${missing[*]}"
        apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
        cargo=${cargo:-$(command -v cargo)}
    fi
    dyadfmu_log "building fmi-sim $want with $("$cargo" --version) into $root (once)"
    if ! "$cargo" install --quiet --locked --root "$root" fmi-sim --version "$want"; then
        dyadfmu_log "cargo install fmi-sim $want failed"
        [ "${CI:-}" != "true" ]
        return
    fi
    export DYADFMU_FMI_SIM="$bin"
}
