"""Properties run without deadlines (support/hypothesis_profile.py): a slow machine must
not fail a test that checks what a program does."""

from hypothesis import settings


def test_the_profile_has_no_deadline() -> None:
    assert settings().deadline is None

