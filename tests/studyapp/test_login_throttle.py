"""Login throttling (django-axes via studyapp.login_throttle): failed admin logins lock out the account-and-address
pair and the address for the cool-off time with a clear 429 page, never the account from every address (the right
password from another address still works); participants' pages are never affected."""
from __future__ import annotations

from datetime import timedelta

import pytest
from axes.models import AccessAttempt
from django.contrib.auth.models import User
from django.core.exceptions import ImproperlyConfigured
from django.test import Client, RequestFactory
from django.utils import timezone

from studyapp.login_throttle import client_ip
from studyapp.settings import env_int
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db
LOGIN = "/admin/login/"


@pytest.fixture(autouse=True)
def throttle(settings):
    settings.AXES_FAILURE_LIMIT = 3
    settings.AXES_COOLOFF_TIME = timedelta(minutes=15)
    settings.PASSWORD_HASHERS = ["django.contrib.auth.hashers.MD5PasswordHasher"]    # fast logins in tests
    User.objects.create_user("admin", password="right-pw-1", is_staff=True, is_superuser=True)
    User.objects.create_user("other", password="other-pw-1", is_staff=True)


def attempt(username: str, password: str, addr: str):
    return Client(REMOTE_ADDR=addr).post(LOGIN, {"username": username, "password": password, "next": "/admin/"})


def logged_in(response) -> bool:
    return response.status_code == 302 and response["Location"] == "/admin/"


def assert_locked(response):
    assert response.status_code == 429
    text = response.content.decode()
    assert "Too many failed logins" in text and "Try again in 15 minutes" in text


def test_below_the_limit_the_right_password_still_works():
    for _ in range(2):
        assert attempt("admin", "wrong", "10.0.0.1").status_code == 200      # the form again, with its error
    assert logged_in(attempt("admin", "right-pw-1", "10.0.0.1"))
    # a success resets the count: two more failures do not lock
    for _ in range(2):
        attempt("admin", "wrong", "10.0.0.1")
    assert logged_in(attempt("admin", "right-pw-1", "10.0.0.1"))


def test_failures_from_one_address_never_lock_the_account_elsewhere():
    for _ in range(5):
        attempt("admin", "wrong", "10.0.1.1")
    assert_locked(attempt("admin", "right-pw-1", "10.0.1.1"))      # the pair (and the address) is locked
    assert_locked(attempt("other", "other-pw-1", "10.0.1.1"))      # the address is locked for every account
    fresh = attempt("admin", "right-pw-1", "10.0.9.9")              # right password from another address
    assert logged_in(fresh)
    assert fresh.client.session["_auth_user_id"] == str(User.objects.get(username="admin").pk)


def test_failures_spread_over_addresses_lock_no_one():
    for i in range(6):
        attempt("admin", "wrong", f"10.0.1.{10 + i}")               # below the limit on every address
    assert logged_in(attempt("admin", "right-pw-1", "10.0.1.10"))
    assert logged_in(attempt("admin", "right-pw-1", "10.0.9.8"))


def test_pair_lock_ends_after_the_cool_off_and_does_not_reach_the_other_address():
    for _ in range(3):
        attempt("admin", "wrong", "10.0.1.2")
    assert logged_in(attempt("admin", "right-pw-1", "10.0.1.3"))
    # the success from .3 resets its own count only: .2 stays locked until the cool-off ends
    assert_locked(attempt("admin", "right-pw-1", "10.0.1.2"))
    AccessAttempt.objects.update(attempt_time=timezone.now() - timedelta(minutes=16))
    assert logged_in(attempt("admin", "right-pw-1", "10.0.1.2"))


def test_address_locked_after_failures_on_many_accounts():
    for name in ("alice", "bob", "carol"):
        attempt(name, "wrong", "10.0.2.1")
    assert_locked(attempt("other", "other-pw-1", "10.0.2.1"))
    assert logged_in(attempt("other", "other-pw-1", "10.0.2.2"))


def test_lock_ends_after_the_cool_off():
    for _ in range(3):
        attempt("admin", "wrong", "10.0.3.1")
    assert_locked(attempt("admin", "right-pw-1", "10.0.3.1"))
    AccessAttempt.objects.update(attempt_time=timezone.now() - timedelta(minutes=16))
    assert logged_in(attempt("admin", "right-pw-1", "10.0.3.1"))


def test_participants_unaffected_by_a_locked_address(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    create_study_from_preset("demo", "demo", plan="test", status="open")
    for _ in range(4):
        attempt("admin", "wrong", "10.0.4.1")
    participant = Client(REMOTE_ADDR="10.0.4.1")
    assert participant.get("/s/demo/").status_code == 200
    assert participant.get("/healthz").status_code == 200


def test_client_address_behind_a_trusted_proxy(settings):
    rf = RequestFactory()
    req = rf.get("/", REMOTE_ADDR="127.0.0.1", HTTP_X_FORWARDED_FOR="6.6.6.6, 203.0.113.7")
    settings.TRUSTED_PROXY_COUNT = 0
    assert client_ip(req) == "127.0.0.1"                    # no proxy trusted: the peer address
    settings.TRUSTED_PROXY_COUNT = 1
    assert client_ip(req) == "203.0.113.7"                  # the address nginx saw, not the client's own claim
    assert client_ip(rf.get("/", REMOTE_ADDR="127.0.0.1")) == "127.0.0.1"


def test_failures_behind_a_proxy_count_per_client(settings):
    settings.TRUSTED_PROXY_COUNT = 1
    for _ in range(3):
        Client(REMOTE_ADDR="127.0.0.1", HTTP_X_FORWARDED_FOR="198.51.100.1").post(
            LOGIN, {"username": "nobody", "password": "x"})
    blocked = Client(REMOTE_ADDR="127.0.0.1", HTTP_X_FORWARDED_FOR="1.1.1.1, 198.51.100.1")
    assert_locked(blocked.post(LOGIN, {"username": "other", "password": "other-pw-1", "next": "/admin/"}))
    fine = Client(REMOTE_ADDR="127.0.0.1", HTTP_X_FORWARDED_FOR="198.51.100.2")
    assert logged_in(fine.post(LOGIN, {"username": "other", "password": "other-pw-1", "next": "/admin/"}))


def test_login_without_a_request_is_not_throttled():
    assert Client().login(username="admin", password="right-pw-1")


def test_bad_environment_values_are_clear_errors(monkeypatch):
    monkeypatch.setenv("LOGIN_FAILURE_LIMIT", "five")
    with pytest.raises(ImproperlyConfigured, match="LOGIN_FAILURE_LIMIT must be a whole number >= 1"):
        env_int("LOGIN_FAILURE_LIMIT", 5, minimum=1)
    monkeypatch.setenv("LOGIN_FAILURE_LIMIT", "0")
    with pytest.raises(ImproperlyConfigured):
        env_int("LOGIN_FAILURE_LIMIT", 5, minimum=1)
    monkeypatch.setenv("LOGIN_FAILURE_LIMIT", "8")
    assert env_int("LOGIN_FAILURE_LIMIT", 5, minimum=1) == 8
