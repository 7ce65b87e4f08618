#!/usr/bin/env bash
# The second command: run the whole test suite (installs what is missing first; idempotent).
#   bash test.sh                      SQLite
#   DATABASE_URL=postgres://postgres@127.0.0.1:5432/postgres bash test.sh    PostgreSQL
# Extra arguments go to pytest, e.g. `bash test.sh -m "not browser"`.
set -euo pipefail
cd "$(dirname "$0")"
bash scripts/bootstrap.sh
export VTK_DEFAULT_OPENGL_WINDOW="${VTK_DEFAULT_OPENGL_WINDOW:-vtkEGLRenderWindow}"
export OMP_NUM_THREADS="${OMP_NUM_THREADS:-1}"
exec .venv/bin/python -m pytest -n "${TEST_WORKERS:-2}" -p no:cacheprovider "$@"
