"""The admin's room: the ModelAdmins (model_admins, imported here so that Django's admin autodiscovery,
which imports this package, registers them), their forms, the pool editor and the study fields."""
from . import model_admins  # noqa: F401 - registers the ModelAdmins
