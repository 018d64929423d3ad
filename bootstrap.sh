#!/usr/bin/env bash
# Set up, run and test bearing-rig-sim from a fresh clone.
#
#   ./bootstrap.sh setup            create .venv, install the pinned dependencies, build and
#                                   install the bearing_rig_msgs interfaces, install the package
#   ./bootstrap.sh run [args...]    setup, then `bearing-rig run args...`
#   ./bootstrap.sh test [args...]   setup, then `python -m pytest args...`, on every core
#                                   (pytest-xdist `-n logical --dist worksteal` unless args give -n)
#
# Needs python3.11, cmake, a C and C++ compiler (gcc, g++), make or ninja, network access to
# PyPI. The C compiler also builds the monitor's compiled pulse path (BEARING_RIG_PURE_PYTHON=1:
# not built, the sources run). Every step leaves a stamp (a hash of its inputs) in .venv/.bootstrap-stamps and is
# skipped while its inputs are unchanged, so a second set-up takes seconds. Delete .venv (and
# build/) to start from nothing. BEARING_RIG_PYTHON overrides the interpreter (default python3.11).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
VENV="$ROOT/.venv"
PY="$VENV/bin/python"
STAMPS="$VENV/.bootstrap-stamps"
LOCK_FILE="$ROOT/requirements.lock"
MSG_SRC="$ROOT/msg_defs"
MSG_BUILD="$ROOT/build/msg_defs"
BASE_PYTHON="${BEARING_RIG_PYTHON:-python3.11}"

# The ROS wheels' interpreter hook computes LD_LIBRARY_PATH once per process tree; an inherited
# marker from another environment would make it skip that for this venv.
unset _ROS_WHEELS_BOOTSTRAP_COMPLETE

log() { printf 'bootstrap: %s\n' "$*" >&2; }
die() { printf 'bootstrap: error: %s\n' "$*" >&2; exit 1; }

usage() {
    awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "${BASH_SOURCE[0]}" >&2
    exit 2
}

hash_files() {
    # sha256 over the names and contents of the given files and folders (sorted, stable).
    local path
    for path in "$@"; do
        if [[ -d "$path" ]]; then
            (cd "$ROOT" && find "${path#"$ROOT"/}" -type f ! -name '*.pyc' -print0 | LC_ALL=C sort -z \
                | xargs -0 --no-run-if-empty sha256sum)
        elif [[ -e "$path" ]]; then
            (cd "$ROOT" && sha256sum "${path#"$ROOT"/}")
        fi
    done | sha256sum | cut -d' ' -f1
}

stamp_ok() { [[ -f "$STAMPS/$1" && "$(cat "$STAMPS/$1")" == "$2" ]]; }
stamp_set() { mkdir -p "$STAMPS" && printf '%s\n' "$2" >"$STAMPS/$1"; }

check_build_tools() {
    command -v cmake >/dev/null || die "cmake not found (needed to build msg_defs)"
    command -v "${CC:-gcc}" >/dev/null || command -v cc >/dev/null || die "no C compiler (gcc) found"
    command -v "${CXX:-g++}" >/dev/null || command -v c++ >/dev/null || die "no C++ compiler (g++) found"
    command -v ninja >/dev/null || command -v make >/dev/null || die "neither ninja nor make found"
}

step_venv() {
    if [[ -x "$PY" ]] && "$PY" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' 2>/dev/null; then
        return
    fi
    command -v "$BASE_PYTHON" >/dev/null || die "$BASE_PYTHON not found (install CPython 3.11)"
    "$BASE_PYTHON" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' \
        || die "$BASE_PYTHON is not CPython 3.11 (the ROS 2 Jazzy wheels are cp311)"
    log "creating $VENV with $BASE_PYTHON"
    "$BASE_PYTHON" -m venv --clear "$VENV"
}

step_dependencies() {
    local key
    key="$(hash_files "$LOCK_FILE")"
    stamp_ok dependencies "$key" && return
    local pip_pin
    pip_pin="$(grep -E '^pip==' "$LOCK_FILE")" || die "$LOCK_FILE has no pip== line"
    log "installing the pinned dependencies ($LOCK_FILE; about 800 MB, a few minutes)"
    "$PY" -m pip install --quiet --disable-pip-version-check --upgrade "$pip_pin"
    "$PY" -m pip install --quiet --disable-pip-version-check --no-deps --progress-bar off -r "$LOCK_FILE"
    "$PY" -m pip check >&2 || die "the pinned dependencies are inconsistent (see pip check above)"
    stamp_set dependencies "$key"
}

step_patch_wheels() {
    # The ROS wheels' *__rosidl_generator_pyExport.cmake files name the wheel builder's Python
    # headers (/opt/python/cp311-cp311/...); point them at this interpreter's and numpy's.
    local files
    files="$(grep -rl --include='*__rosidl_generator_pyExport.cmake' '/opt/python/cp311-cp311' "$VENV/share" || true)"
    [[ -z "$files" ]] && return
    log "patching $(wc -l <<<"$files") rosidl export file(s) with this venv's include paths"
    "$PY" - "$files" <<'PYEOF'
import sys, sysconfig
import numpy

replacements = [
    ("/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include", numpy.get_include()),
    ("/opt/python/cp311-cp311/include/python3.11", sysconfig.get_paths()["include"]),
]
for name in sys.argv[1].splitlines():
    with open(name, encoding="utf-8") as f:
        text = f.read()
    for old, new in replacements:
        text = text.replace(old, new)
    if "/opt/python/cp311-cp311" in text:
        sys.exit(f"{name}: an unknown /opt/python path remains")
    with open(name, "w", encoding="utf-8") as f:
        f.write(text)
PYEOF
}

step_messages() {
    local key
    key="$(hash_files "$MSG_SRC" "$LOCK_FILE")"
    if stamp_ok messages "$key" && [[ -f "$VENV/share/bearing_rig_msgs/package.xml" ]]; then
        return
    fi
    check_build_tools
    local generator=()
    command -v ninja >/dev/null && generator=(-G Ninja)
    log "building msg_defs (bearing_rig_msgs) into $VENV"
    rm -rf "$MSG_BUILD"
    mkdir -p "$MSG_BUILD"
    # Installed into the venv prefix: the interfaces then import with no environment variables
    # (lib*.so in $VENV/lib, on the library path the ROS wheels' interpreter hook sets).
    AMENT_PREFIX_PATH="$VENV" CMAKE_PREFIX_PATH="$VENV" \
        cmake -S "$MSG_SRC" -B "$MSG_BUILD" "${generator[@]}" \
        -DCMAKE_BUILD_TYPE=Release \
        -DBUILD_TESTING=OFF \
        -DCMAKE_INSTALL_PREFIX="$VENV" \
        -DCMAKE_PREFIX_PATH="$VENV" \
        -DPython3_EXECUTABLE="$PY" \
        -DPython3_FIND_VIRTUALENV=ONLY \
        >"$MSG_BUILD/configure.log" 2>&1 \
        || { tail -n 40 "$MSG_BUILD/configure.log" >&2; die "cmake configure of msg_defs failed (log: $MSG_BUILD/configure.log)"; }
    AMENT_PREFIX_PATH="$VENV" cmake --build "$MSG_BUILD" --parallel "$(nproc 2>/dev/null || echo 2)" \
        >"$MSG_BUILD/build.log" 2>&1 \
        || { tail -n 40 "$MSG_BUILD/build.log" >&2; die "build of msg_defs failed (log: $MSG_BUILD/build.log)"; }
    cmake --install "$MSG_BUILD" >"$MSG_BUILD/install.log" 2>&1 \
        || { tail -n 40 "$MSG_BUILD/install.log" >&2; die "install of msg_defs failed (log: $MSG_BUILD/install.log)"; }
    (cd /tmp && "$PY" -c 'import bearing_rig_msgs.msg, bearing_rig_msgs.srv') \
        || die "bearing_rig_msgs was built but does not import"
    stamp_set messages "$key"
}

step_package() {
    local key
    key="$(hash_files "$ROOT/setup.py" "$ROOT/setup.cfg" "$ROOT/package.xml" "$ROOT/resource" "$LOCK_FILE")"
    if ! stamp_ok package "$key" || [[ ! -x "$VENV/bin/bearing-rig" ]]; then
        log "installing bearing_rig_sim (editable) into $VENV"
        (cd "$ROOT" && "$PY" -m pip install --quiet --disable-pip-version-check \
            --no-deps --no-build-isolation -e .)
        [[ -x "$VENV/bin/bearing-rig" ]] || die "the bearing-rig command was not installed"
        stamp_set package "$key"
    fi
    # An editable install leaves out setup.py's data_files. Register the package in the venv's
    # ament index by hand, its share folder linking back to this checkout (so config/ and launch/
    # edits need no reinstall): get_package_share_directory("bearing_rig_sim") and `ros2 launch
    # bearing_rig_sim rig.launch.py` then work as after colcon build.
    local index="$VENV/share/ament_index/resource_index/packages" share="$VENV/share/bearing_rig_sim"
    mkdir -p "$index" "$share"
    [[ -e "$index/bearing_rig_sim" ]] || : >"$index/bearing_rig_sim"
    ln -sfn "$ROOT/package.xml" "$share/package.xml"
    [[ -d "$share/config" && ! -L "$share/config" ]] && rm -rf "$share/config"
    ln -sfn "$ROOT/config" "$share/config"
    # ros2 launch looks for the file with os.walk, which does not enter a linked folder: a real
    # launch/ folder, its files linking back to this checkout.
    [[ -L "$share/launch" ]] && rm -f "$share/launch"
    mkdir -p "$share/launch"
    find "$share/launch" -maxdepth 1 -type l ! -exec test -e {} \; -delete
    local file
    for file in "$ROOT"/launch/*.launch.py; do
        ln -sfn "$file" "$share/launch/$(basename "$file")"
    done
    # The node executables where a colcon install has them (lib/bearing_rig_sim/<name>), so the
    # stock `ros2 run bearing_rig_sim <name>` and `ros2 pkg executables` find them: links to the
    # console scripts pip put in bin/ (the node entry points of setup.py, by their ROS names).
    local lib="$VENV/lib/bearing_rig_sim" name
    mkdir -p "$lib"
    for name in $("$PY" -c 'from importlib.metadata import entry_points
for ep in entry_points(group="console_scripts"):
    if ep.value.startswith("bearing_rig_sim.nodes.") and "-" not in ep.name:
        print(ep.name)'); do
        [[ -x "$VENV/bin/$name" ]] || die "console script $VENV/bin/$name missing"
        ln -sfn "../../bin/$name" "$lib/$name"
    done
    [[ -x "$lib/simulator" ]] || die "no node executables under $lib"
}

step_compiled() {
    # The monitor's pulse path compiled to C by mypyc (bearing_rig_sim/compiled.py) into
    # build/compiled/, again whenever a source it was compiled from changed (the package
    # imports the sources instead until then). BEARING_RIG_PURE_PYTHON=1 skips it.
    if [[ -n "${BEARING_RIG_PURE_PYTHON:-}" && "${BEARING_RIG_PURE_PYTHON}" != 0 ]]; then
        log "BEARING_RIG_PURE_PYTHON is set: the pulse path is not compiled"
        return
    fi
    local probe='import sys; from bearing_rig_sim.compiled import current; sys.exit(0 if current() else 1)'
    (cd /tmp && "$PY" -c "$probe") && return
    log "compiling the monitor's pulse path (mypyc, about a minute)"
    local build_log="$ROOT/build/compiled-build.log"
    if ! (cd /tmp && "$PY" -c 'import sys; from bearing_rig_sim.compiled import main; sys.exit(main())') >"$build_log" 2>&1; then
        tail -n 40 "$build_log" >&2
        die "compiling the pulse path failed (whole log: $build_log); BEARING_RIG_PURE_PYTHON=1 runs it from its sources"
    fi
    (cd /tmp && "$PY" -c "$probe") || die "the compiled pulse path does not match its sources after the build"
}

setup() {
    mkdir -p "$ROOT/build"
    # One set-up at a time per checkout (two shells, or CI jobs sharing a checkout).
    if command -v flock >/dev/null; then
        exec 9>"$ROOT/build/.bootstrap.lock"
        flock 9
    fi
    step_venv
    step_dependencies
    step_patch_wheels
    step_messages
    step_package
    step_compiled
    # Release the lock: the command run after set-up (a rig session, pytest) must not hold it.
    if command -v flock >/dev/null; then
        exec 9>&-
    fi
}

cmd="${1:-}"
[[ $# -gt 0 ]] && shift
case "$cmd" in
    setup)
        [[ $# -eq 0 ]] || die "setup takes no arguments"
        setup
        log "ready: $VENV"
        ;;
    run)
        setup
        exec "$VENV/bin/bearing-rig" run "$@"
        ;;
    test)
        setup
        cd "$ROOT"
        status=0
        # One worker per core (each test leases its own ROS domain, test/conftest.py); the
        # workers steal from each other, so the long session tests do not end the run alone.
        parallel=(-n logical --dist worksteal)
        for arg in "$@"; do
            [[ "$arg" == -n* || "$arg" == --numprocesses* ]] && parallel=()
        done
        "$PY" -m pytest "${parallel[@]}" "$@" || status=$?
        if [[ $status -eq 5 ]]; then
            die "pytest collected no tests (exit 5): that counts as a failure"
        fi
        exit "$status"
        ;;
    -h | --help | help) usage ;;
    *) printf 'bootstrap: error: unknown command %q (use setup, run or test)\n' "$cmd" >&2; usage ;;
esac
