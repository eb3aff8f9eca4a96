"""Properties run without deadlines (support/hypothesis_profile.py): a slow machine must
not fail a test that checks what a program does."""

from hypothesis import given, settings
from hypothesis import strategies as st


def test_the_profile_has_no_deadline() -> None:
    assert settings().deadline is None


@given(st.integers())
def test_a_property_inherits_it(number: int) -> None:
    assert settings().deadline is None and isinstance(number, int)
