"""Training commands mirror their library's options; study commands name unknown slugs."""
import pytest
from django.core.management import CommandError, call_command, load_command_class

from generation.gait.train import build_parser as gait_parser
from studyapp.management.cli import mirrored_namespace


def test_train_gait_mirrors_library_options_including_append():
    parser = load_command_class("studyapp", "train_gait").create_parser("manage.py", "train_gait")
    options = vars(parser.parse_args(["--epochs", "3", "--set", "a=1", "--set", "b=2", "--resume"]))
    ns = mirrored_namespace(gait_parser(), options)
    assert (ns.epochs, ns.set, ns.resume) == (3, ["a=1", "b=2"], True)
    assert not hasattr(ns, "verbosity")  # Django's own options are dropped


def test_train_gesture_parses_library_options():
    parser = load_command_class("studyapp", "train_gesture").create_parser("manage.py", "train_gesture")
    assert parser.parse_args(["--epochs", "2", "--seed", "5"]).epochs == 2


@pytest.mark.django_db
@pytest.mark.parametrize("command", ["export_study", "analyze"])
def test_study_commands_name_unknown_slug(command, tmp_path):
    with pytest.raises(CommandError, match="no study with slug 'nope'"):
        call_command(command, "nope", "--out", str(tmp_path))
