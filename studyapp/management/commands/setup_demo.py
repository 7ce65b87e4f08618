"""Create (or update) the demo study from the demo preset and print the participant URL. Idempotent. --owner
USERNAME makes that account an owner of the study (per-study access; demo.sh passes its admin, who is also a
superuser and so sees every study anyway)."""
from django.contrib.auth import get_user_model
from django.core.management.base import BaseCommand, CommandError

from protocol.section_types import is_page_type
from studyapp.data.catalogue import section_queryset
from studyapp.models import Clip, Study
from studyapp.staff.presets import create_study_from_preset


class Command(BaseCommand):
    """``manage.py setup_demo``: the open, publicly listed demo study built from a preset, with its participant URL."""

    help = "Create the demo study (every section type) from the clips in the database and print its URL."

    def add_arguments(self, parser):
        """--slug, --base-url of the printed link, --preset and --owner (a username)."""
        parser.add_argument("--slug", default="demo")
        parser.add_argument("--base-url", default="http://127.0.0.1:8000")
        parser.add_argument("--preset", default="demo", help="preset to build the study from (default: demo)")
        parser.add_argument("--owner", default="", help="username of an account to make an owner of the study")

    def handle(self, *args, slug, base_url, preset, owner="", **options):
        """Create the study from the preset, or reopen the existing one, add the owner and print each section's pool
        size (warning about empty pools) and the participant URL. Requires a non-empty clip catalogue."""
        owner_user = None
        if owner:
            owner_user = get_user_model().objects.filter(username=owner).first()
            if owner_user is None:
                raise CommandError(f"--owner {owner!r}: no account with this username")
        if not Clip.objects.exists():
            raise CommandError("The clip catalogue is empty. Render the demo clips first:\n"
                               "    python manage.py generate_clips --plan demo\n"
                               "then run setup_demo again.")
        study = Study.objects.filter(slug=slug).first()
        if study is None:
            # the demo asks to be listed on the front page; a real study is reached through its link only
            study = create_study_from_preset(preset, slug, status=Study.Status.OPEN, listed_publicly=True)
            self.stdout.write(f"Created study '{study.title}' (slug {slug}) from preset {preset}.")
        else:
            if study.status != Study.Status.OPEN:
                study.status = Study.Status.OPEN
                study.save(update_fields=["status"])
            self.stdout.write(f"Study '{study.title}' (slug {slug}) already exists; left as it is (open).")
        if owner_user is not None:
            study.owners.add(owner_user)
            self.stdout.write(f"  owner: {owner_user.username}")
        for section in study.sections.order_by("order"):
            if section.reuse_section_id or is_page_type(section.section_type):
                continue
            n = section_queryset(section.section_type, section.pool).count()
            if n == 0:
                self.stdout.write(self.style.WARNING(
                    f"  section {section.order} ({section.section_type}): no clip matches its pool {section.pool}; "
                    "participants will skip it"))
            else:
                self.stdout.write(f"  section {section.order} ({section.section_type}): {n} clips in the pool")
        self.stdout.write(self.style.SUCCESS(f"Participant URL: {base_url.rstrip('/')}/s/{study.slug}/"))
