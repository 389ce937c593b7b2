#!/usr/bin/env bash
# Run the main job (bake LUTs if missing/stale, validate, write the report) in the
# project venv:  bash scripts/main.sh [run_main.py args...]
set -uo pipefail
# shellcheck source=env.sh
source "$(dirname "${BASH_SOURCE[0]}")/env.sh" || exit $?
cd "$(dirname "${BASH_SOURCE[0]}")/.." || exit 1
exec python scripts/run_main.py "$@"
