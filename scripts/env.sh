# shellcheck shell=bash
# Source this file (the other scripts do): it makes sure <repo>/.venv exists with the
# exact packages of requirements.lock and the checkout installed in editable mode as the
# package ``rt_lookdev`` (pyproject.toml: how scripts and tests import it, no sys.path
# edits), then puts .venv/bin first on PATH so that `python` is the venv's CPython 3.11.
#
#   RTL_PYTHON=/path/to/python3.11   use this interpreter to create the venv
#
# On failure it returns (when sourced) or exits with status 2.

_rtl_env_setup() {
    local repo venv lock stamp want have candidate version py
    repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
    venv="$repo/.venv"
    lock="$repo/requirements.lock"
    stamp="$venv/.rtl-lock-sha256"

    _rtl_py_version() {  # prints "3.11" for a working interpreter, nothing otherwise
        "$1" -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null
    }

    if [[ ! -f "$lock" ]]; then
        echo "env.sh: $lock is missing" >&2
        return 2
    fi
    want="$(cat "$lock" "$repo/pyproject.toml" | sha256sum | cut -d' ' -f1)"

    # Cached path: a 3.11 venv built from this exact lock file.  Stay quiet.
    if [[ -x "$venv/bin/python" && -f "$stamp" && "$(cat "$stamp")" == "$want" \
          && "$(_rtl_py_version "$venv/bin/python")" == "3.11" ]]; then
        _rtl_activate "$venv"
        return 0
    fi

    # Find CPython 3.11: $RTL_PYTHON, else python3.11, else python3 if it is 3.11.
    py=""
    local found=()
    if [[ -n "${RTL_PYTHON:-}" ]]; then
        version="$(_rtl_py_version "$RTL_PYTHON")"
        if [[ "$version" == "3.11" ]]; then
            py="$RTL_PYTHON"
        else
            found+=("RTL_PYTHON=$RTL_PYTHON is ${version:-not a working python}")
        fi
    else
        for candidate in python3.11 python3; do
            command -v "$candidate" >/dev/null 2>&1 || continue
            version="$(_rtl_py_version "$candidate")"
            if [[ "$version" == "3.11" ]]; then
                py="$candidate"
                break
            fi
            found+=("$candidate is ${version:-not a working python}")
        done
    fi
    if [[ -z "$py" ]]; then
        local what="no python3.11 or python3 on PATH"
        if ((${#found[@]})); then
            what="$(IFS=','; echo "${found[*]}" | sed 's/,/, /g')"
        fi
        echo "env.sh: bpy==5.0.1 needs CPython 3.11 (found $what)." >&2
        echo "env.sh: Install Python 3.11 (e.g. \`pyenv install 3.11\` or apt \`python3.11-venv\`)" \
             "or set RTL_PYTHON=/path/to/python3.11" >&2
        return 2
    fi

    if [[ -x "$venv/bin/python" && "$(_rtl_py_version "$venv/bin/python")" != "3.11" ]]; then
        echo "env.sh: $venv is not a Python 3.11 venv; recreating it"
        rm -rf "$venv"
    fi
    if [[ ! -x "$venv/bin/python" ]]; then
        echo "env.sh: creating $venv with $(command -v "$py") ($("$py" --version 2>&1))"
        if ! "$py" -m venv "$venv"; then
            echo "env.sh: could not create the venv; on Debian/Ubuntu install python3.11-venv" >&2
            rm -rf "$venv"
            return 2
        fi
    fi

    echo "env.sh: installing the pinned packages of requirements.lock into .venv (bpy is ~350 MB, first time takes minutes)"
    rm -f "$stamp"
    if ! PIP_DISABLE_PIP_VERSION_CHECK=1 "$venv/bin/python" -m pip install --no-deps --progress-bar off \
            -r "$lock"; then
        echo "env.sh: pip install -r requirements.lock failed (see above)" >&2
        return 2
    fi
    echo "env.sh: installing this checkout in editable mode (the package rt_lookdev)"
    if ! PIP_DISABLE_PIP_VERSION_CHECK=1 "$venv/bin/python" -m pip install --no-deps --no-build-isolation \
            --progress-bar off -q -e "$repo"; then
        echo "env.sh: the editable install of $repo failed (see above)" >&2
        return 2
    fi
    if ! PIP_DISABLE_PIP_VERSION_CHECK=1 "$venv/bin/python" -m pip check; then
        echo "env.sh: requirements.lock is incomplete or inconsistent (pip check failed above)" >&2
        return 2
    fi
    echo "$want" >"$stamp"
    echo "env.sh: .venv ready"
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

if ! _rtl_env_setup; then
    # `return` works when this file is sourced; `exit` when it is run directly.
    return 2 2>/dev/null || exit 2
fi
