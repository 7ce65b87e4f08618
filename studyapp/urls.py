"""Root URL map: the Django admin under /admin/, the liveness probe /healthz, /favicon.ico and the study app
(namespace "studyapp") at the root; server errors go to views_health.server_error (503 + Retry-After when the
database could not be reached)."""
from django.contrib import admin
from django.urls import include, path

from studyapp import views_health

urlpatterns = [
    path("admin/", admin.site.urls),
    path("healthz", views_health.healthz, name="healthz"),
    path("favicon.ico", views_health.favicon),
    path("", include("studyapp.urls_study")),
]

handler500 = "studyapp.views_health.server_error"
