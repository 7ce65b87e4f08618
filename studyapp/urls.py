"""Root URL map: the Django admin under /admin/ and the study app (namespace "studyapp") at the root."""
from django.contrib import admin
from django.urls import include, path

urlpatterns = [
    path("admin/", admin.site.urls),
    path("", include("studyapp.urls_study")),
]
