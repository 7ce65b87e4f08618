#!/usr/bin/env bash
# The first command: set everything up on a fresh machine and run the demo study.
#   bash demo.sh              (idempotent: a second run skips finished work)
# Environment: DEMO_ADMIN_USER / DEMO_ADMIN_PASSWORD (default admin / a generated password kept in var/),
#              HOST (127.0.0.1), PORT (8000), DEMO_WORKERS (2),
#              DEBUG (off; DEBUG=1 bash demo.sh shows Django's debug pages: never on a reachable host).
# The server's access log leaves out participant tokens and Prolific IDs (studyapp/gunicorn_logging.py). gunicorn
# faces the network directly here, so it runs asyncio (ASGI) workers: a client sending its request a byte at a
# time, or downloading a video slowly, holds a connection, never a thread (docs/security.md "Slow clients"). For a
# public study put nginx in front (docs/deploy.md).
set -euo pipefail
cd "$(dirname "$0")"
bash scripts/bootstrap.sh
export VTK_DEFAULT_OPENGL_WINDOW="${VTK_DEFAULT_OPENGL_WINDOW:-vtkEGLRenderWindow}"
PY=.venv/bin/python
HOST="${HOST:-127.0.0.1}"
PORT="${PORT:-8000}"
mkdir -p var
# The host the demo is served on is an allowed host (DEBUG is off, so Django checks Host headers).
export ALLOWED_HOSTS="${ALLOWED_HOSTS:-localhost,127.0.0.1,[::1],$HOST}"
export DEBUG="${DEBUG:-0}"

echo "==> database migrations"
$PY manage.py migrate --noinput -v 0

echo "==> synthetic gait corpus (built once, about 20 s; for the synthetic gait observer, a quality-gate option beside the default real-capture observer)"
[ -f var/corpus/gait_corpus_synthetic.npz ] || $PY manage.py build_corpus -v 0 > /dev/null

echo "==> demo clips (rendered once; unchanged clips are never rendered again)"
$PY manage.py generate_clips --plan demo --workers "${DEMO_WORKERS:-2}"

echo "==> admin account"
ADMIN_USER="${DEMO_ADMIN_USER:-admin}"
if [ -n "${DEMO_ADMIN_PASSWORD:-}" ]; then
    ADMIN_PASSWORD="$DEMO_ADMIN_PASSWORD"
elif [ -f var/demo_admin_password ]; then
    ADMIN_PASSWORD="$(cat var/demo_admin_password)"
else
    ADMIN_PASSWORD="$($PY -c 'import secrets; print(secrets.token_urlsafe(12))')"
    (umask 077; echo "$ADMIN_PASSWORD" > var/demo_admin_password)
fi
DEMO_ADMIN_USER="$ADMIN_USER" DEMO_ADMIN_PASSWORD="$ADMIN_PASSWORD" $PY manage.py shell -c "
import os
from django.contrib.auth import get_user_model
User = get_user_model()
user, _ = User.objects.get_or_create(username=os.environ['DEMO_ADMIN_USER'], defaults={'email': 'admin@example.org'})
user.is_staff = user.is_superuser = True
user.set_password(os.environ['DEMO_ADMIN_PASSWORD'])
user.save()
"

echo "==> demo study"
PARTICIPANT_URL="$($PY manage.py setup_demo --base-url "http://$HOST:$PORT" --owner "$ADMIN_USER" | tee /dev/stderr \
    | sed -n 's/^Participant URL: //p' | tail -1)"

cat <<MSG

  Demo study is ready.
    Participant link:  ${PARTICIPANT_URL:-http://$HOST:$PORT/}
    Admin:             http://$HOST:$PORT/admin/   user: $ADMIN_USER   password: $ADMIN_PASSWORD
  Stop the server with Ctrl-C; run 'bash demo.sh' again to restart (nothing is redone).

MSG
# WEB_CONCURRENCY: the worker processes; with DATABASE_URL (PostgreSQL) they share DB_CONNECTIONS (default 20)
# through Django's connection pool, so a burst of participants never exhausts the server's connections.
export WEB_CONCURRENCY="${WEB_CONCURRENCY:-2}"
exec .venv/bin/gunicorn studyapp.asgi:application -b "$HOST:$PORT" -w "$WEB_CONCURRENCY" --worker-class asgi \
    --access-logfile - --logger-class studyapp.gunicorn_logging.RedactingLogger
