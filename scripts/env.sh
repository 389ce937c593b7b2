# shellcheck shell=bash
# Source this file (the other scripts do): it makes sure a virtualenv exists with the exact packages
# of a lock file and this checkout installed in editable mode as the package ``rt_lookdev``
# (pyproject.toml: how scripts and tests import it, no sys.path edits), then puts its bin/ first on
# PATH so that `python` is that venv's interpreter.
#
#   RTL_LOCK=path/to/file.lock   the environment to use (default: requirements.lock, the development
#                                pin; requirements/blender-*.lock are the other supported releases)
#   RTL_PYTHON=/path/to/python   the interpreter to create the venv with (its version must be the one
#                                the lock names in its "# python: X.Y" line)
#
# requirements.lock lives in .venv; requirements/blender-4.5.lock in .venvs/blender-4.5, and so on.
# A venv is rebuilt when its lock file or pyproject.toml changes.  On failure it returns (when sourced)
# or exits with status 2.

_rtl_env_setup() {
    local repo lock venv stamp want need py version candidate name
    repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
    lock="${RTL_LOCK:-$repo/requirements.lock}"
    [[ "$lock" = /* ]] || lock="$repo/$lock"
    if [[ ! -f "$lock" ]]; then
        echo "env.sh: lock file $lock is missing" >&2
        return 2
    fi
    need="$(sed -n 's/^# python: *\([0-9][0-9.]*\).*/\1/p' "$lock" | head -n 1)"
    if [[ -z "$need" ]]; then
        echo "env.sh: $lock has no '# python: X.Y' line" >&2
        return 2
    fi
    name="$(basename "$lock" .lock)"
    if [[ "$lock" -ef "$repo/requirements.lock" ]]; then
        venv="$repo/.venv"
    else
        venv="$repo/.venvs/$name"
    fi
    stamp="$venv/.rtl-lock-sha256"
    want="$(cat "$lock" "$repo/pyproject.toml" | sha256sum | cut -d' ' -f1)"

    _rtl_py_version() {  # prints "3.13" for a working interpreter, nothing otherwise
        "$1" -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null
    }

    # Cached path: a venv built from this exact lock file with the right Python.  Stay quiet.
    if [[ -x "$venv/bin/python" && -f "$stamp" && "$(cat "$stamp")" == "$want" \
          && "$(_rtl_py_version "$venv/bin/python")" == "$need" ]]; then
        _rtl_activate "$venv"
        return 0
    fi

    # Find CPython $need: $RTL_PYTHON, else python$need, else a pyenv install, else python3.
    py=""
    local found=()
    if [[ -n "${RTL_PYTHON:-}" ]]; then
        version="$(_rtl_py_version "$RTL_PYTHON")"
        if [[ "$version" == "$need" ]]; then
            py="$RTL_PYTHON"
        else
            found+=("RTL_PYTHON=$RTL_PYTHON is ${version:-not a working python}")
        fi
    else
        for candidate in "python$need" "${PYENV_ROOT:-$HOME/.pyenv}"/versions/"$need"*/bin/"python$need" \
                         /usr/bin/"python$need" /usr/local/bin/"python$need" python3; do
            [[ -x "$candidate" ]] || command -v "$candidate" >/dev/null 2>&1 || continue
            version="$(_rtl_py_version "$candidate")"
            if [[ "$version" == "$need" ]]; then
                py="$candidate"
                break
            fi
            [[ "$candidate" == python* ]] && found+=("$candidate is ${version:-not a working python}")
        done
    fi
    if [[ -z "$py" ]]; then
        local what="no python$need on PATH or under pyenv"
        if ((${#found[@]})); then
            what="$(IFS=','; echo "${found[*]}" | sed 's/,/, /g')"
        fi
        echo "env.sh: $(basename "$lock") needs CPython $need (found $what)." >&2
        echo "env.sh: Install Python $need (e.g. \`pyenv install $need\` or apt \`python$need-venv\`)" \
             "or set RTL_PYTHON=/path/to/python$need" >&2
        return 2
    fi

    if [[ -x "$venv/bin/python" && "$(_rtl_py_version "$venv/bin/python")" != "$need" ]]; then
        echo "env.sh: $venv is not a Python $need venv; recreating it"
        rm -rf "$venv"
    fi
    if [[ ! -x "$venv/bin/python" ]]; then
        echo "env.sh: creating $venv with $py ($("$py" --version 2>&1))"
        mkdir -p "$(dirname "$venv")"
        if ! "$py" -m venv "$venv"; then
            echo "env.sh: could not create the venv; on Debian/Ubuntu install python$need-venv" >&2
            rm -rf "$venv"
            return 2
        fi
    fi

    echo "env.sh: installing the pinned packages of $(basename "$lock") into $venv (bpy is ~400 MB, first time takes minutes)"
    rm -f "$stamp"
    if ! PIP_DISABLE_PIP_VERSION_CHECK=1 "$venv/bin/python" -m pip install --no-deps --progress-bar off -q \
            -r "$lock"; then
        echo "env.sh: pip install -r $lock failed (see above)" >&2
        return 2
    fi
    echo "env.sh: installing this checkout in editable mode (the package rt_lookdev)"
    if ! PIP_DISABLE_PIP_VERSION_CHECK=1 "$venv/bin/python" -m pip install --no-deps --no-build-isolation \
            --progress-bar off -q -e "$repo"; then
        echo "env.sh: the editable install of $repo failed (see above)" >&2
        return 2
    fi
    if ! PIP_DISABLE_PIP_VERSION_CHECK=1 "$venv/bin/python" -m pip check; then
        echo "env.sh: $(basename "$lock") is incomplete or inconsistent (pip check failed above)" >&2
        return 2
    fi
    echo "$want" >"$stamp"
    echo "env.sh: $venv ready"
    _rtl_activate "$venv"
}

_rtl_activate() {
    export VIRTUAL_ENV="$1"
    case ":$PATH:" in
        *":$1/bin:"*) ;;
        *) export PATH="$1/bin:$PATH" ;;
    esac
    export PYTHONNOUSERSITE=1
    hash -r 2>/dev/null || true
}

# engines/three's pinned node packages (three.js and playwright-core, package-lock.json) for the browser tests:
# installed with `npm ci` when node is here and the lock changed.  Without node the browser tests say so (and fail
# under CI=true); nothing else needs it.
_rtl_node_setup() {
    local repo pkg stamp want
    repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
    pkg="$repo/engines/three"
    [[ -f "$pkg/package-lock.json" ]] || return 0
    if ! command -v npm >/dev/null; then
        echo "env.sh: npm not found: the three.js browser tests will be skipped (Debian: apt-get install nodejs npm)" >&2
        return 0
    fi
    stamp="$pkg/node_modules/.rtl-lock-sha256"
    want="$(cat "$pkg/package-lock.json" | sha256sum | cut -d' ' -f1)"
    [[ -f "$stamp" && "$(cat "$stamp")" == "$want" ]] && return 0
    echo "env.sh: installing engines/three's node packages (npm ci)"
    if ! (cd "$pkg" && npm ci --no-audit --no-fund --loglevel=error); then
        echo "env.sh: npm ci in $pkg failed (see above)" >&2
        return 2
    fi
    echo "$want" >"$stamp"
}

if ! _rtl_env_setup || ! _rtl_node_setup; then
    # `return` works when this file is sourced; `exit` when it is run directly.
    return 2 2>/dev/null || exit 2
fi
