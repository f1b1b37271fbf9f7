"""A build without the preprocess tier has no tetseg.preprocess (and the runtime still works)."""

import pytest


@pytest.mark.no_preprocess
def test_preprocess_module_is_absent():
    with pytest.raises(ImportError):
        import tetseg.preprocess  # noqa: F401
