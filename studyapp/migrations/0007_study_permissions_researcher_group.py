"""The custom permission export_participant_data on Study, and the "researcher" group holding the permissions a
researcher needs (studyapp.permissions.RESEARCHER_PERMISSIONS at the time of this migration)."""

from django.contrib.auth.management import create_permissions
from django.db import migrations

RESEARCHER_PERMISSIONS = [
    "add_study", "change_study", "view_study",
    "add_section", "change_section", "delete_section", "view_section",
    "view_clip", "view_participant", "view_response",
    "export_participant_data",
]


def create_researcher_group(apps, schema_editor):
    # Permissions are normally created after all migrations (post_migrate); make this app's exist now.
    app_config = apps.get_app_config("studyapp")
    app_config.models_module = True
    create_permissions(app_config, apps=apps, verbosity=0)
    app_config.models_module = None
    Group = apps.get_model("auth", "Group")
    Permission = apps.get_model("auth", "Permission")
    group, _ = Group.objects.get_or_create(name="researcher")
    perms = list(Permission.objects.filter(content_type__app_label="studyapp", codename__in=RESEARCHER_PERMISSIONS))
    missing = set(RESEARCHER_PERMISSIONS) - {p.codename for p in perms}
    if missing:
        raise RuntimeError(f"permissions missing for the researcher group: {sorted(missing)}")
    group.permissions.add(*perms)


def remove_researcher_group(apps, schema_editor):
    apps.get_model("auth", "Group").objects.filter(name="researcher").delete()


class Migration(migrations.Migration):

    dependencies = [
        ('auth', '0012_alter_user_first_name_max_length'),
        ('contenttypes', '0002_remove_content_type_name'),
        ('studyapp', '0006_assignment_viewing'),
    ]

    operations = [
        migrations.AlterModelOptions(
            name='study',
            options={'ordering': ['-created_at'], 'permissions': [('export_participant_data', 'Can download participant data (CSV exports and analysis reports)')], 'verbose_name_plural': 'studies'},
        ),
        migrations.RunPython(create_researcher_group, remove_researcher_group),
    ]
