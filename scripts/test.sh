#!/usr/bin/env bash
# Run the test suite (pytest; extra args are passed through):
#   bash scripts/test.sh                      # all of tests/, in the development environment (.venv)
#   bash scripts/test.sh tests/blender -x     # only these paths
#   bash scripts/test.sh --release 4.5 [...]  # in the environment of requirements/blender-4.5.lock
#   bash scripts/test.sh --matrix [...]       # every supported release in turn, then a table of results
#                                             # (out/matrix/matrix.md and .json)
#   bash scripts/test.sh --workers 1 [...]    # in one process (default: one pytest-xdist worker per core,
#                                             # each test module on one worker)
set -uo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$repo" || exit 1

release=""
matrix=0
workers=logical
args=()
while (($#)); do
    case "$1" in
        --release) release="${2:?--release needs a name, e.g. 4.5}"; shift 2 ;;
        --release=*) release="${1#--release=}"; shift ;;
        --matrix) matrix=1; shift ;;
        --workers) workers="${2:?--workers needs a number}"; shift 2 ;;
        --workers=*) workers="${1#--workers=}"; shift ;;
        *) args+=("$1"); shift ;;
    esac
done

lock_of() {  # the lock file of a release name ("" = the development environment)
    if [[ -z "$1" ]]; then echo "$repo/requirements.lock"; else echo "$repo/requirements/blender-$1.lock"; fi
}

run_suite() {  # run_suite <release or ""> <junit xml or ""> [pytest args...]
    local rel="$1" xml="$2"
    shift 2
    local lock
    lock="$(lock_of "$rel")"
    if [[ ! -f "$lock" ]]; then
        echo "test.sh: no environment for release '$rel' ($lock is missing; have: $(ls "$repo"/requirements | tr '\n' ' '))" >&2
        return 2
    fi
    (
        export RTL_LOCK="$lock"
        # shellcheck source=env.sh
        source "$repo/scripts/env.sh" || exit $?
        paths=(tests)
        for arg in "$@"; do
            if [[ "$arg" != -* && -e "${arg%%::*}" ]]; then
                paths=()
                break
            fi
        done
        extra=()
        [[ -n "$xml" ]] && extra=(--junitxml "$xml")
        # the suite's tests are mostly one thread each (Python, bpy, one Cycles tile): a worker process per core
        # (pytest-xdist); a module's tests stay on one worker, so its module fixtures run once.  A worker that
        # crashes ends the run (its test is reported as failed) rather than being replaced: pytest-xdist 3.8.0 can
        # deadlock at the end of a --dist loadscope run after replacing a crashed worker (pytest-xdist #1378; a CI
        # run hung until its time limit so)
        [[ "$workers" != 1 ]] && extra+=(-n "$workers" --dist loadscope --max-worker-restart 0)
        # the slowest tests, in every log: where the suite's time goes (and how close any is to the timeout)
        extra+=(--durations 12)
        python -m pytest "${paths[@]}" -q "${extra[@]}" "$@"
        rc=$?
        if [[ -n "$xml" ]]; then   # what the environment is, for the matrix table
            python -c 'import sys, numpy, importlib.metadata as m
print(m.version("bpy"), "%d.%d.%d" % sys.version_info[:3], numpy.__version__)' >"${xml%.xml}.env"
        fi
        if [[ $rc -eq 5 ]]; then
            echo "test.sh: no tests were collected (pytest exit code 5); failing" >&2
            exit 1
        fi
        exit $rc
    )
}

if ((matrix == 0)); then
    run_suite "$release" "" "${args[@]+"${args[@]}"}"
    exit $?
fi

# --- the version matrix ---------------------------------------------------------------------------
out="$repo/out/matrix"
mkdir -p "$out"
releases=("")
for lock in "$repo"/requirements/blender-*.lock; do
    name="$(basename "$lock" .lock)"
    releases+=("${name#blender-}")
done
status=0
for rel in "${releases[@]}"; do
    label="${rel:-dev}"
    if [[ -n "$rel" ]]; then
        echo "=== test.sh --matrix: Blender $rel (requirements/blender-$rel.lock)"
    else
        echo "=== test.sh --matrix: the development environment (requirements.lock)"
    fi
    start=$(date +%s)
    run_suite "$rel" "$out/$label.xml" "${args[@]+"${args[@]}"}"
    rc=$?
    echo "$rc $(($(date +%s) - start))" >"$out/$label.rc"
    ((rc == 0)) || status=1
done
(
    export RTL_LOCK="$(lock_of "")"
    source "$repo/scripts/env.sh" >/dev/null || exit $?
    python -m rt_lookdev.validation.tools.version_matrix "$out"
) || status=1
exit $status
