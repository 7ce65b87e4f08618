"""ASGI entry point for gunicorn's asyncio worker (``gunicorn studyapp.asgi:application -k asgi``): the worker reads
each request header and body on its event loop, so a client sending one byte at a time holds no thread; the views
run in threads only once the whole request has arrived."""
import os

from django.core.asgi import get_asgi_application

os.environ.setdefault("DJANGO_SETTINGS_MODULE", "studyapp.settings")
application = get_asgi_application()
