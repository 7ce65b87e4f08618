"""Probe and privacy fields: when a page's clip was fetched, whether a study is listed on the front page and
exports its external ids as given, the abandon default (120 min), the payment-ids permission; and the pools of
existing sections keep drawing what they drew: "include flagged" unticked used to keep realism-only flags in, which
is now the explicit switch keep_advisory (protocol.pools), so it is set on every saved pool that does not include
flagged clips anyway."""

from django.db import migrations, models


def keep_what_pools_drew(apps, schema_editor):
    Section = apps.get_model("studyapp", "Section")
    for section in Section.objects.filter(reuse_section__isnull=True).only("pk", "pool"):
        pool = section.pool
        if isinstance(pool, dict) and pool.get("include_flagged") is not True and "keep_advisory" not in pool:
            Section.objects.filter(pk=section.pk).update(pool={**pool, "keep_advisory": True})


def forget_the_switch(apps, schema_editor):
    Section = apps.get_model("studyapp", "Section")
    for section in Section.objects.only("pk", "pool"):
        if isinstance(section.pool, dict) and "keep_advisory" in section.pool:
            pool = {k: v for k, v in section.pool.items() if k != "keep_advisory"}
            Section.objects.filter(pk=section.pk).update(pool=pool)


class Migration(migrations.Migration):

    dependencies = [
        ('studyapp', '0011_section_type_choices_from_registry'),
    ]

    operations = [
        migrations.AlterModelOptions(
            name='study',
            options={'ordering': ['-created_at'], 'permissions': [('export_participant_data', 'Can download participant data (CSV exports and analysis reports)'), ('download_payment_ids', "Can download participants' external ids (Prolific IDs) for payment")], 'verbose_name_plural': 'studies'},
        ),
        migrations.AddField(
            model_name='assignment',
            name='fetched_at',
            field=models.DateTimeField(blank=True, editable=False, null=True),
        ),
        migrations.AddField(
            model_name='study',
            name='export_external_ids',
            field=models.BooleanField(default=False, help_text="Exports and reports carry participants' external ids (Prolific IDs) as given. Off: each is a pseudonym, the same for one participant in every export of this study; the ids for payment are a separate download (permission: download payment ids)"),
        ),
        migrations.AddField(
            model_name='study',
            name='listed_publicly',
            field=models.BooleanField(default=False, help_text="List this study on the site's front page while it is open. Off: only people with its link (Prolific, e-mail) find it"),
        ),
        migrations.AlterField(
            model_name='study',
            name='abandon_after_minutes',
            field=models.PositiveIntegerField(default=120, help_text='A started participant inactive this long stops counting towards the participant limit, so the places of people (or scripts) who left free up; they may still come back and finish (0 = never)'),
        ),
        migrations.RunPython(keep_what_pools_drew, forget_the_switch),
    ]
