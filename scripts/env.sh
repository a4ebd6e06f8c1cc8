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
# (its instruction counts); `clang`: Clang (the lanes and the angles compiled as an
# importer's compiler in its default mode may rebuild an FMU's sources); `windows`: the
# MinGW-w64 cross compiler and Wine (the FMUs' Windows binaries, tested under Wine);
# `browser`: chromium and chromium-driver (the
# animation's page in a real browser, headless); `embedded`: the Cortex-M4F toolchain
# with newlib and QEMU's ARM machines (dyadfmu embedded), the 64-bit ARM Linux cross
# compiler and QEMU's user mode (the FMUs' aarch64-linux binaries, replayed under it).
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
        clang)
            command -v clang >/dev/null 2>&1 || missing+=(clang)
            ;;
        browser)
            command -v chromium >/dev/null 2>&1 || missing+=(chromium)
            command -v chromedriver >/dev/null 2>&1 || missing+=(chromium-driver)
            ;;
        embedded)
            command -v arm-none-eabi-gcc >/dev/null 2>&1 || missing+=(gcc-arm-none-eabi)
            [ -d /usr/lib/arm-none-eabi/newlib ] || missing+=(libnewlib-arm-none-eabi)
            command -v qemu-system-arm >/dev/null 2>&1 || missing+=(qemu-system-arm)
            command -v aarch64-linux-gnu-gcc >/dev/null 2>&1 || missing+=(gcc-aarch64-linux-gnu)
            [ -d /usr/aarch64-linux-gnu/lib ] || missing+=(libc6-dev-arm64-cross)
            command -v qemu-aarch64 >/dev/null 2>&1 || missing+=(qemu-user)
            ;;
        *)
            dyadfmu_log "dyadfmu_ensure_system: unknown need '$need' (study, clang, windows, browser, embedded)"
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

# dyadfmu_build DIR [cmake options...]: configure and build into DIR, the FMUs with the
# venv's Python (its fmpy supplies the FMI headers). A build whose options are those of
# its last whole build and that no source is newer than (dyadfmu_sources_newer) is left
# as it is, in well under a second, as long as every FMU and library it made is there
# (DYADFMU_REBUILD=1 has make check it all the same);
# CMake configures again only for new options (else make does, when a scene or the
# generator changed). Progress: a line per FMU packaged; the whole log in DIR/build.log,
# whose end is shown if the build fails.
dyadfmu_build() {
    local dir=$1
    shift
    local stamp="$dir/.dyadfmu-built" last="" wanted
    [ -f "$stamp" ] && last=$(cat "$stamp")
    # no options: those the build directory's cache holds
    wanted="options: ${*:-${last#options: }}"
    if [ -n "$last" ] && [ "$last" = "$wanted" ] && [ -z "${DYADFMU_REBUILD:-}" ] &&
        ! dyadfmu_sources_newer "$stamp" && dyadfmu_products_there "$stamp.products"; then
        dyadfmu_log "$dir is up to date: no source is newer than its last build (DYADFMU_REBUILD=1 checks it all)"
        return 0
    fi
    dyadfmu_log "building in $dir $*"
    if [ "$last" != "$wanted" ] || [ ! -f "$dir/CMakeCache.txt" ]; then
        # the last build's products are not those of the options configured now
        rm -f "$stamp"
        "$(dyadfmu_cmake_of "$dir")" -S "$DYADFMU_ROOT" -B "$dir" -DCMAKE_BUILD_TYPE=Release \
            -DPython3_EXECUTABLE="$DYADFMU_VENV/bin/python" "$@" >/dev/null || {
            local status=$?
            dyadfmu_log "configuring $dir failed (CMake's messages above)"
            return "$status"
        }
    fi
    # The stamp's time is the build's start: a source saved during the build is newer. A
    # build that fails leaves the last one's stamp, older than the sources that made this
    # one run: the next call builds again, and a build that cannot reach the compiler (a
    # tool missing) costs the next one nothing.
    printf '%s' "$wanted" >"$stamp.new"
    dyadfmu_build_logged "$dir" "$dir/build.log" || return $?
    find "$dir" "$dir/fmus" -maxdepth 1 \( -name '*.fmu' -o -name 'lib*.so' \) -print \
        2>/dev/null >"$stamp.products" || true
    mv "$stamp.new" "$stamp"
}

# dyadfmu_products_there LIST: true if every file LIST names (a build's FMUs and
# libraries, one a line) is there.
dyadfmu_products_there() {
    local product
    [ -f "$1" ] || return 1
    while IFS= read -r product; do
        [ -f "$product" ] || return 1
    done <"$1"
}

# dyadfmu_cmake_of DIR: the cmake that configured DIR (its cache's CMAKE_COMMAND), else the
# first on PATH. The venv has a CMake of its own (the package's build needs one) and puts it
# first on PATH where it is activated: another version configures the whole build again and
# makes every object anew.
dyadfmu_cmake_of() {
    local cached
    cached=$(sed -n 's/^CMAKE_COMMAND:INTERNAL=//p' "$1/CMakeCache.txt" 2>/dev/null || true)
    if [ -n "$cached" ] && [ -x "$cached" ]; then
        printf '%s' "$cached"
    else
        printf 'cmake'
    fi
}

# dyadfmu_build_logged DIR LOG [cmake --build options...]: build, the output in LOG, a line
# per FMU packaged on stderr; on failure the log's last 40 lines and where it is.
dyadfmu_build_logged() {
    local dir=$1 log=$2
    shift 2
    local status
    # PIPESTATUS read in either branch: with or without pipefail, cmake's own status
    if "$(dyadfmu_cmake_of "$dir")" --build "$dir" -j "$(nproc 2>/dev/null || echo 2)" "$@" 2>&1 |
        tee "$log" |
        sed -un 's/^\[ *\([0-9]*\)%\] Packaging \(.*\.fmu\)$/== [\1%] packaged \2/p' >&2; then
        status=${PIPESTATUS[0]}
    else
        status=${PIPESTATUS[0]}
    fi
    if [ "$status" -ne 0 ]; then
        tail -n 40 "$log" >&2
        dyadfmu_log "the build failed: its whole output is in $log"
        return "$status"
    fi
}

# dyadfmu_sources_newer STAMP: true if a file the build reads (the checkout's C, CMake,
# generator, scenes, tests, the license, the venv's packages) is newer than STAMP.
dyadfmu_sources_newer() {
    local found
    found=$(find "$DYADFMU_ROOT/CMakeLists.txt" "$DYADFMU_ROOT/LICENSE" "$DYADFMU_ROOT/src" \
        "$DYADFMU_ROOT/fmu" "$DYADFMU_ROOT/modelDescription" "$DYADFMU_ROOT/tests" \
        "$DYADFMU_VENV/.dyadfmu-installed" -name __pycache__ -prune -o -newer "$1" -print \
        -quit 2>/dev/null)
    [ -n "$found" ]
}

# ---- probes of the FMU binaries (tests/fmu_fuzz.c, fmu_api_tests.c, fmu_threads.c) ----
# The FMUs the ThreadSanitizer build makes: one of each kind (a generic dyad, a
# tailored multi-dyad scene, the drive, the motor), enough for the thread test and no more.
DYADFMU_TSAN_FMUS=${DYADFMU_TSAN_FMUS:-"dyad_rrt;sixbar;drive;motor"}

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

dyadfmu_fmi_sim_bin() {   # where cargo install puts fmi-sim
    printf '%s/bin/fmi-sim\n' "${CARGO_INSTALL_ROOT:-${CARGO_HOME:-$HOME/.cargo}}"
}

# dyadfmu_fmi_sim_found: exports DYADFMU_FMI_SIM if the pinned fmi-sim is installed (after
# dyadfmu_ensure_fmi_sim ran in a subshell, whose export the caller does not see).
dyadfmu_fmi_sim_found() {
    local want bin
    want=$(dyadfmu_fmi_sim_pin)
    bin=$(dyadfmu_fmi_sim_bin)
    if [ -n "$want" ] && [ "$(dyadfmu_fmi_sim_installed "$bin")" = "$want" ]; then
        export DYADFMU_FMI_SIM="$bin"
        return 0
    fi
    return 1
}

dyadfmu_ensure_fmi_sim() {
    local want root bin cargo missing=()
    dyadfmu_fmi_sim_found && return 0
    want=$(dyadfmu_fmi_sim_pin)
    root=${CARGO_INSTALL_ROOT:-${CARGO_HOME:-$HOME/.cargo}}
    bin=$(dyadfmu_fmi_sim_bin)
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

# ---- timed stages (scripts/run-tests) ------------------------------------------------
# A stage is one named step of a run, executed in a subshell with `set -e`. Its start, its
# end, its CPU time (user + system of the subshell and of every process it waited for, read
# from /proc, so that a stage in the background counts only its own processes) and its exit
# status go to files in $DYADFMU_STAGES: a stage run inside a background job reports as
# one in the foreground does. At exit, the run prints them as a table.

# dyadfmu_stages_init DIR: starts the clock, empties DIR (the stages' records and the logs of
# background jobs) and prints the table of stages when the shell exits.
dyadfmu_stages_init() {
    DYADFMU_STAGES=$1
    DYADFMU_STAGES_T0=$EPOCHREALTIME
    DYADFMU_STAGES_SHELL=$BASHPID
    read -r DYADFMU_STAGES_LOAD0 _ </proc/loadavg
    declare -gA DYADFMU_JOBS=()
    rm -rf "$DYADFMU_STAGES"
    mkdir -p "$DYADFMU_STAGES"
    trap dyadfmu_stages_summary EXIT
    # stopped by a signal, the run's status says so (the EXIT trap would see 0)
    trap 'exit 143' TERM
    trap 'exit 130' INT
}

# dyadfmu_cpu_ticks: sets REPLY to the user + system clock ticks of this shell and of the
# children it has waited for (/proc/PID/stat: utime, stime, cutime, cstime).
dyadfmu_cpu_ticks() {
    local stat fields
    read -r stat <"/proc/$BASHPID/stat"
    read -r -a fields <<<"${stat##*) }"
    REPLY=$((fields[11] + fields[12] + fields[13] + fields[14]))
}

_dyadfmu_stage_end() {   # in the stage's subshell, at its exit: end time, CPU, status (or stopped)
    local rc=$1
    dyadfmu_cpu_ticks
    printf '%s %s %s\n' "$EPOCHREALTIME" "$REPLY" "$rc" >"$DYADFMU_STAGES/$DYADFMU_STAGE.end"
}

# dyadfmu_stage NAME COMMAND...: runs COMMAND (a function or program) as stage NAME; if it
# fails, the shell exits with its status. In the run's own shell, a background job that has
# ended is collected first (dyadfmu_job_wait), so that its failure stops the run early.
dyadfmu_stage() {
    local name=$1 rc
    shift
    printf '%s\n' "$EPOCHREALTIME" >"$DYADFMU_STAGES/$name.start"
    dyadfmu_log "stage $name"
    set +e
    (
        set -e
        DYADFMU_STAGE=$name
        trap '_dyadfmu_stage_end $?' EXIT
        trap 'trap - EXIT; _dyadfmu_stage_end stopped; exit 143' TERM
        "$@"
    )
    rc=$?
    set -e
    if [ "$rc" -ne 0 ]; then
        dyadfmu_log "stage $name failed (exit $rc)"
        exit "$rc"
    fi
    [ "$BASHPID" != "$DYADFMU_STAGES_SHELL" ] || dyadfmu_jobs_collect
}

# dyadfmu_job JOB COMMAND...: runs COMMAND (usually one or more dyadfmu_stage calls) in the
# background, in its own process group (so that a run that stops ends all of it), its
# output to $DYADFMU_STAGES/JOB.log.
dyadfmu_job() {
    local job=$1
    shift
    dyadfmu_log "job $job started in the background (log: $DYADFMU_STAGES/$job.log)"
    set -m
    (
        set -e
        "$@"
    ) >"$DYADFMU_STAGES/$job.log" 2>&1 </dev/null &
    DYADFMU_JOBS[$job]=$!
    set +m
}

# dyadfmu_job_wait JOB: waits for a background job and shows its log; if it failed, the
# shell exits with its status. Nothing to do for a job already collected.
dyadfmu_job_wait() {
    local job=$1 rc
    [ -n "${DYADFMU_JOBS[$job]:-}" ] || return 0
    set +e
    wait "${DYADFMU_JOBS[$job]}"
    rc=$?
    set -e
    unset "DYADFMU_JOBS[$job]"
    if [ "$rc" -ne 0 ]; then
        dyadfmu_log "job $job failed (exit $rc); its log:"
        cat "$DYADFMU_STAGES/$job.log" >&2
        exit "$rc"
    fi
    dyadfmu_log "job $job done; its log:"
    sed 's/^/  | /' "$DYADFMU_STAGES/$job.log"
}

dyadfmu_jobs_collect() {   # waits for the background jobs that have already ended
    local job
    for job in "${!DYADFMU_JOBS[@]}"; do
        kill -0 "${DYADFMU_JOBS[$job]}" 2>/dev/null || dyadfmu_job_wait "$job"
    done
}

# dyadfmu_stages_summary: (the EXIT trap) ends the background jobs still running, shows the
# log of one that has failed too, then prints each stage's start, wall and CPU seconds and
# result, and the run's totals.
dyadfmu_stages_summary() {
    local rc=$? job name t0 end load1
    for job in "${!DYADFMU_JOBS[@]}"; do
        if kill -0 "${DYADFMU_JOBS[$job]}" 2>/dev/null; then
            dyadfmu_log "stopping background job $job (log: $DYADFMU_STAGES/$job.log)"
            kill -TERM -- "-${DYADFMU_JOBS[$job]}" 2>/dev/null || true
            wait "${DYADFMU_JOBS[$job]}" 2>/dev/null || true
        elif ! wait "${DYADFMU_JOBS[$job]}"; then
            dyadfmu_log "job $job failed too; its log:"
            cat "$DYADFMU_STAGES/$job.log" >&2
        fi
    done
    dyadfmu_cpu_ticks
    read -r load1 _ </proc/loadavg
    for name in "$DYADFMU_STAGES"/*.start; do
        [ -f "$name" ] || continue
        read -r t0 <"$name"
        end="- - -"
        [ -f "${name%.start}.end" ] && read -r end <"${name%.start}.end"
        printf '%s %s %s\n' "$t0" "$(basename "$name" .start)" "$end"
    done | sort -n | awk -v t0="$DYADFMU_STAGES_T0" -v t1="$EPOCHREALTIME" -v rc="$rc" \
        -v hz="$(getconf CLK_TCK)" -v cpu="$REPLY" -v cores="$(nproc)" \
        -v load0="$DYADFMU_STAGES_LOAD0" -v load1="$load1" -f "$DYADFMU_ROOT/scripts/stages.awk"
    exit "$rc"
}
