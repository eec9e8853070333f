"""Test-suite settings shared by every test module."""

import os

from hypothesis import settings

# Property-based tests draw the same examples on every run and machine: a suite that can
# fail at random is no test, and a failure found once is found again (the search stays
# as broad; widen it locally with HYPOTHESIS_PROFILE=explore).
settings.register_profile("deterministic", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False, max_examples=500)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))
