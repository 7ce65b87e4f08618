from django.apps import AppConfig


class StudyAppConfig(AppConfig):
    """The studyapp Django app, listed as "Perceptual studies" in the admin."""

    name = "studyapp"
    verbose_name = "Perceptual studies"
    default_auto_field = "django.db.models.BigAutoField"

    def ready(self):
        """Connect the app's signal receivers (studyapp.signals) once the registry is ready."""
        from . import signals  # noqa: F401 - connects the receivers
