"""Settings read from the environment.

Variables (all optional for the demo):
    SECRET_KEY        required when PRODUCTION is set; otherwise generated once into DATA_DIR/secret_key (mode 600)
    DEBUG             "1"/"true" to turn debugging on (off by default)
    ALLOWED_HOSTS     comma-separated host names (default: localhost,127.0.0.1,[::1])
    CSRF_TRUSTED_ORIGINS  comma-separated origins, e.g. https://study.example.org
    DATABASE_URL      e.g. postgres://user@127.0.0.1:5432/db; SQLite file var/db.sqlite3 when unset
    DB_CONNECTIONS    PostgreSQL: the most connections all server processes together open (default 20; keep it
                      below max_connections minus what migrations, reports and psql need)
    WEB_CONCURRENCY   server worker processes sharing DB_CONNECTIONS (default 2; gunicorn reads it too)
    DB_POOL_TIMEOUT   seconds a request waits for a free pooled connection before a 503 (default 5)
    DB_POOL           "0" turns the pool off: one connection per request, closed at its end
    DATA_DIR          where the SQLite file, media and reports live (default: ./var)
    MEDIA_ROOT        where rendered clips live (default: DATA_DIR/media)
    PRODUCTION        "1" turns on HTTPS-only cookies, HSTS and the other deploy checks
    MEDIA_ACCEL_REDIRECT  URL prefix of nginx's internal location for MEDIA_ROOT (e.g. /protected-media/): clip
                      requests are then answered with X-Accel-Redirect and nginx sends the bytes (docs/deploy.md);
                      empty (default): the app streams clips itself
    REPORTS_DIR       where finished analysis-report zips are kept (default: DATA_DIR/reports)
    LOGIN_FAILURE_LIMIT   failed logins after which an account from one address, or an address, is locked out
                      (default 5)
    LOGIN_LOCKOUT_MINUTES how long such a lockout lasts (default 15)
    TRUSTED_PROXY_COUNT   reverse proxies in front of the app whose X-Forwarded-For is trusted for the client
                      address of the login throttle (default: 1 with PRODUCTION=1, the nginx recipe; else 0)
    START_RATE_BURST  new participants one client address may start at once (default 6; 0 turns the limit off)
    START_RATE_INTERVAL_S then one more every this many seconds (default 20; studyapp.participant.start_throttle)
    QA_GAIT_OBSERVER  the quality gate's gait observer for plans that name none: real (default), real-perceived
                      or synthetic
    REAL_CORPUS       the Bandai Namco real-capture corpus the real gait observers are trained on (default:
                      var/mocap/bandai-namco.npz); generate_clips passes it down
    BML_CORPUS        the BML walks of Emotion-Gait, the second corpus of the calibrated gait observer (default:
                      var/mocap/emotion-gait-bml.npz)
"""
import os
from datetime import timedelta
from pathlib import Path

import dj_database_url

BASE_DIR = Path(__file__).resolve().parent.parent


def env_bool(name: str, default: bool = False) -> bool:
    """The environment variable as a boolean: 1, true, yes or on (any case) are True; unset or blank gives
    ``default``."""
    value = os.environ.get(name)
    if value is None or value == "":
        return default
    return value.strip().lower() in {"1", "true", "yes", "on"}


def env_int(name: str, default: int, minimum: int = 0) -> int:
    """The environment variable as a whole number of at least ``minimum`` (``default`` when unset or blank);
    ImproperlyConfigured for anything else, so a bad setting stops the start-up."""
    raw = os.environ.get(name, "").strip()
    if not raw:
        return default
    try:
        value = int(raw)
    except ValueError:
        value = minimum - 1
    if value < minimum:
        from django.core.exceptions import ImproperlyConfigured

        raise ImproperlyConfigured(f"{name} must be a whole number >= {minimum}, got {raw!r}")
    return value


def env_list(name: str, default: str) -> list[str]:
    """The environment variable (else ``default``) as a comma-separated list, items stripped, empty ones dropped."""
    return [item.strip() for item in os.environ.get(name, default).split(",") if item.strip()]


DEBUG = env_bool("DEBUG")
PRODUCTION = env_bool("PRODUCTION")

ALLOWED_HOSTS = env_list("ALLOWED_HOSTS", "localhost,127.0.0.1,[::1],testserver")
CSRF_TRUSTED_ORIGINS = env_list("CSRF_TRUSTED_ORIGINS", "")

DATA_DIR = Path(os.environ.get("DATA_DIR", BASE_DIR / "var"))


def local_secret_key(data_dir: Path) -> str:
    """Outside production without SECRET_KEY: a random key generated once and kept in DATA_DIR/secret_key (mode
    600), so sessions survive a restart and no key is ever written in the code. The file appears atomically (a
    finished temporary file hard-linked into place), so concurrent first starts agree on one key."""
    import secrets

    path = Path(data_dir) / "secret_key"
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".secret_key.{os.getpid()}.{secrets.token_hex(4)}")
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w") as fh:
            fh.write(secrets.token_urlsafe(64) + "\n")
        try:
            os.link(tmp, path)
        except FileExistsError:
            pass                 # another process made it first: use theirs
        finally:
            tmp.unlink()
    if path.stat().st_mode & 0o077:
        path.chmod(0o600)
    key = path.read_text().strip()
    if len(key) < 50:
        from django.core.exceptions import ImproperlyConfigured

        raise ImproperlyConfigured(f"{path} holds no usable secret key: delete it to have a new one generated")
    return key


SECRET_KEY = os.environ.get("SECRET_KEY", "")
if not SECRET_KEY:
    if PRODUCTION:
        from django.core.exceptions import ImproperlyConfigured

        raise ImproperlyConfigured("SECRET_KEY must be set when PRODUCTION=1")
    SECRET_KEY = local_secret_key(DATA_DIR)

MEDIA_ROOT = Path(os.environ.get("MEDIA_ROOT", DATA_DIR / "media"))
MEDIA_URL = "/media/"
# Behind nginx (deploy/nginx/study.conf): hand clip bytes to nginx after the app's checks. Must end with "/".
MEDIA_ACCEL_REDIRECT = os.environ.get("MEDIA_ACCEL_REDIRECT", "").strip()
if MEDIA_ACCEL_REDIRECT and not (MEDIA_ACCEL_REDIRECT.startswith("/") and MEDIA_ACCEL_REDIRECT.endswith("/")):
    from django.core.exceptions import ImproperlyConfigured

    raise ImproperlyConfigured(f"MEDIA_ACCEL_REDIRECT must start and end with '/', got {MEDIA_ACCEL_REDIRECT!r}")
REPORTS_DIR = Path(os.environ.get("REPORTS_DIR", DATA_DIR / "reports"))
# The gait observer of the quality gate for plans that name none in their qa: block (protocol.vocabulary.QA_OBSERVERS).
QA_GAIT_OBSERVER = os.environ.get("QA_GAIT_OBSERVER", "").strip() or "real"
# The real-capture corpora of the real gait observers (generation.mocap.real_corpus.RealCorpora.of); "" = the built
# ones under var/mocap/.
REAL_CORPUS = os.environ.get("REAL_CORPUS", "").strip()
BML_CORPUS = os.environ.get("BML_CORPUS", "").strip()
STATIC_URL = "/static/"
# collectstatic's target; outside production WhiteNoise serves from the app folders and needs none.
STATIC_ROOT = Path(os.environ["STATIC_ROOT"]) if os.environ.get("STATIC_ROOT") else (
    DATA_DIR / "static" if PRODUCTION else None)
STATICFILES_DIRS = [BASE_DIR / "static"]
STORAGES = {
    "default": {"BACKEND": "django.core.files.storage.FileSystemStorage"},
    "staticfiles": {"BACKEND": "whitenoise.storage.CompressedManifestStaticFilesStorage"
                    if PRODUCTION else "django.contrib.staticfiles.storage.StaticFilesStorage"},
}

# Outside production, serve static files straight from the app folders (no collectstatic needed for the demo).
WHITENOISE_USE_FINDERS = not PRODUCTION

INSTALLED_APPS = [
    "django.contrib.admin",
    "django.contrib.auth",
    "django.contrib.contenttypes",
    "django.contrib.sessions",
    "django.contrib.messages",
    "django.contrib.staticfiles",
    "axes",
    "studyapp",
]

MIDDLEWARE = [
    "django.middleware.security.SecurityMiddleware",
    "studyapp.security.ContentSecurityPolicyMiddleware",
    # Cache-Control: no-store on the admin and the researcher pages and downloads (studyapp.security)
    "studyapp.security.NoStoreMiddleware",
    # 400 for a control character (NUL, ...) in the path, a query or form value or a cookie: before any lookup
    "studyapp.inputs.ControlCharacterMiddleware",
    "whitenoise.middleware.WhiteNoiseMiddleware",
    "django.contrib.sessions.middleware.SessionMiddleware",
    # each request starts in LANGUAGE_CODE; participant views activate their study's language (studyapp.i18n)
    "studyapp.i18n.StudyLanguageMiddleware",
    "django.middleware.common.CommonMiddleware",
    "django.middleware.csrf.CsrfViewMiddleware",
    "django.contrib.auth.middleware.AuthenticationMiddleware",
    "django.contrib.messages.middleware.MessageMiddleware",
    "django.middleware.clickjacking.XFrameOptionsMiddleware",
    # turns a locked-out login (studyapp.login_throttle) into its 429 page; other requests pass untouched
    "axes.middleware.AxesMiddleware",
]

ROOT_URLCONF = "studyapp.urls"
WSGI_APPLICATION = "studyapp.wsgi.application"

TEMPLATES = [
    {
        "BACKEND": "django.template.backends.django.DjangoTemplates",
        "DIRS": [BASE_DIR / "templates"],
        "APP_DIRS": True,
        "OPTIONS": {
            "context_processors": [
                "django.template.context_processors.request",
                "django.contrib.auth.context_processors.auth",
                "django.contrib.messages.context_processors.messages",
            ],
        },
    },
]


def postgres_pool_options(budget: int, workers: int, timeout_s: float) -> dict:
    """Django's PostgreSQL pool (psycopg_pool.ConnectionPool arguments) of one server process: at most
    budget // workers connections (at least 2), one kept open when idle; a request waits at most timeout_s (s) for
    a free one, then fails with OperationalError (PoolTimeout), which the app answers with 503 and Retry-After
    (studyapp.views_health.server_error) instead of opening more."""
    max_size = max(2, budget // max(1, workers))
    return {"min_size": 1, "max_size": max_size, "timeout": timeout_s, "max_idle": 300.0}


def database_from_env() -> dict:
    """PostgreSQL (or any dj-database-url URL) when DATABASE_URL is set, else SQLite in WAL mode.

    PostgreSQL goes through Django's connection pool (OPTIONS["pool"]): connections stay bounded however many
    requests run at once, under gunicorn's threads as under its ASGI workers (which run each request's view in a
    thread of its own: with persistent per-thread connections they opened one per concurrent request). Sized from
    DB_CONNECTIONS (all server processes together) and WEB_CONCURRENCY (their number); DB_POOL=0 turns it off
    (one connection per request, closed at its end, e.g. behind pgbouncer)."""
    url = os.environ.get("DATABASE_URL", "").strip()
    if url:
        config = dj_database_url.parse(url, conn_max_age=0)
        if config["ENGINE"] == "django.db.backends.postgresql" and env_bool("DB_POOL", True):
            budget = env_int("DB_CONNECTIONS", 20, minimum=2)
            workers = env_int("WEB_CONCURRENCY", 2, minimum=1)
            timeout = env_int("DB_POOL_TIMEOUT", 5, minimum=1)
            config.setdefault("OPTIONS", {})["pool"] = postgres_pool_options(budget, workers, float(timeout))
        return config
    return {
        "ENGINE": "django.db.backends.sqlite3",
        "NAME": DATA_DIR / "db.sqlite3",
        # WAL lets participants' reads go on while one answer is written.
        "OPTIONS": {
            "init_command": "PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL;",
            "transaction_mode": "IMMEDIATE",
            "timeout": 20,
        },
    }


DATABASES = {"default": database_from_env()}
DEFAULT_AUTO_FIELD = "django.db.models.BigAutoField"

AUTH_PASSWORD_VALIDATORS = [
    {"NAME": "django.contrib.auth.password_validation.UserAttributeSimilarityValidator"},
    {"NAME": "django.contrib.auth.password_validation.MinimumLengthValidator"},
    {"NAME": "django.contrib.auth.password_validation.CommonPasswordValidator"},
]

LANGUAGE_CODE = "en"
# Languages a study may be shown in (Study.language); the catalogues are committed (locale/<code>/LC_MESSAGES).
LANGUAGES = [("en", "English"), ("de", "Deutsch")]
LOCALE_PATHS = [BASE_DIR / "locale"]
TIME_ZONE = "UTC"
USE_I18N = True
USE_TZ = True

LOGIN_URL = "/admin/login/"

# Login throttling (django-axes, studyapp.login_throttle): failed logins count per account-and-address pair and per
# address; at the limit that pair, or that address, is locked out for the cool-off time without checking the
# password. Never per account alone: anyone could then lock the admin out from everywhere.
AUTHENTICATION_BACKENDS = [
    "studyapp.login_throttle.ThrottledLoginBackend",
    "django.contrib.auth.backends.ModelBackend",
]
AXES_FAILURE_LIMIT = env_int("LOGIN_FAILURE_LIMIT", 5, minimum=1)
AXES_COOLOFF_TIME = timedelta(minutes=env_int("LOGIN_LOCKOUT_MINUTES", 15, minimum=1))
AXES_LOCKOUT_PARAMETERS = [["username", "ip_address"], "ip_address"]
AXES_RESET_ON_SUCCESS = True
AXES_LOCKOUT_CALLABLE = "studyapp.login_throttle.lockout_response"
AXES_CLIENT_IP_CALLABLE = "studyapp.login_throttle.client_ip"
AXES_HTTP_RESPONSE_CODE = 429
TRUSTED_PROXY_COUNT = env_int("TRUSTED_PROXY_COUNT", 1 if PRODUCTION else 0)
START_RATE_BURST = env_int("START_RATE_BURST", 6, minimum=0)
START_RATE_INTERVAL_S = env_int("START_RATE_INTERVAL_S", 20, minimum=1)

if PRODUCTION:
    SECURE_SSL_REDIRECT = env_bool("SECURE_SSL_REDIRECT", True)
    SECURE_PROXY_SSL_HEADER = ("HTTP_X_FORWARDED_PROTO", "https")
    SESSION_COOKIE_SECURE = True
    CSRF_COOKIE_SECURE = True
    SECURE_HSTS_SECONDS = int(os.environ.get("SECURE_HSTS_SECONDS", "31536000"))
    SECURE_HSTS_INCLUDE_SUBDOMAINS = True
    SECURE_HSTS_PRELOAD = True
    SECURE_CONTENT_TYPE_NOSNIFF = True
    SECURE_REFERRER_POLICY = "same-origin"

LOGGING = {
    "version": 1,
    "disable_existing_loggers": False,
    # Participant tokens and Prolific IDs never reach a log line (e.g. Django's "Not Found: /p/<token>/...").
    "filters": {"redact_tokens": {"()": "studyapp.security.RedactTokensFilter"}},
    "handlers": {"console": {"class": "logging.StreamHandler", "filters": ["redact_tokens"]}},
    "root": {"handlers": ["console"], "level": os.environ.get("LOG_LEVEL", "WARNING")},
    # Django's own "django" handler (console when DEBUG) would log unfiltered: route it through ours instead.
    "loggers": {"django": {"handlers": ["console"], "level": os.environ.get("LOG_LEVEL", "WARNING"),
                           "propagate": False}},
}
