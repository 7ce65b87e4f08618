"""Clip.title: a readable label (generator, condition, variant; protocol.titles), filled in for the clips already
in the catalogue."""

from django.db import migrations, models

from protocol.titles import clip_titles

FIELDS = ("clip_id", "modality", "origin", "plan", "happy", "sad", "angry", "neutral", "final_happy", "final_sad",
          "final_angry", "final_neutral", "emotion_label", "valence", "arousal", "dominance", "theme", "weight",
          "metadata")


def fill_titles(apps, schema_editor):
    Clip = apps.get_model("studyapp", "Clip")
    plans = Clip.objects.filter(title="").values_list("plan", flat=True).distinct()
    for plan in list(plans):
        rows = list(Clip.objects.filter(plan=plan).values(*FIELDS))
        titles = clip_titles(rows)
        for clip_id, title in titles.items():
            Clip.objects.filter(clip_id=clip_id, title="").update(title=title)


class Migration(migrations.Migration):

    dependencies = [
        ("studyapp", "0013_participant_device_and_wording"),
    ]

    operations = [
        migrations.AddField(
            model_name="clip",
            name="title",
            field=models.CharField(blank=True, max_length=200),
        ),
        migrations.RunPython(fill_titles, migrations.RunPython.noop),
    ]
