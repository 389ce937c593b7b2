#!/usr/bin/env bash
# Run the test suite in the project venv:  bash scripts/test.sh [pytest args...]
#   bash scripts/test.sh                    # all of tests/
#   bash scripts/test.sh tests/blender -x   # only these paths
set -uo pipefail
# shellcheck source=env.sh
source "$(dirname "${BASH_SOURCE[0]}")/env.sh" || exit $?
cd "$(dirname "${BASH_SOURCE[0]}")/.." || exit 1

# Default to tests/ unless a test path (file, dir or file::node) was passed.
paths=(tests)
for arg in "$@"; do
    if [[ "$arg" != -* && -e "${arg%%::*}" ]]; then
        paths=()
        break
    fi
done

python -m pytest "${paths[@]}" -q "$@"
rc=$?
if [[ $rc -eq 5 ]]; then
    echo "test.sh: no tests were collected (pytest exit code 5); failing" >&2
    exit 1
fi
exit $rc
