"""Set-up shared by the test suite and the doctests, once per test run."""

import pytest


@pytest.fixture(autouse=True, scope="session")
def _banded_kernel_compiled() -> None:
    # backend="auto" answers with Clarabel while the banded kernel is being compiled in the
    # background (first use after installation); compiling it up front keeps every test's
    # backend independent of timing.
    from speedplan.solve.banded import compile_kernel

    compile_kernel()
