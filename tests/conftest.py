import os
import signal
import threading

import numpy as np
import pytest
from hypothesis import settings

settings.register_profile("ci", max_examples=60, deadline=None)
settings.register_profile("dev", max_examples=30, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

#: the most pytest-xdist workers ``-n auto`` starts (pyproject's addopts): the long tests are
#: whole simulated control runs, one core each; more workers than this only add start-up time
MAX_WORKERS = 4

# A pytest-xdist worker finds COLUMNS=80 (and LINES=24) in its environment, set as it starts,
# not by the user. The CLI's human output honours COLUMNS (else a width of 160 for a pipe), so a
# worker would wrap what a serial run does not: the workers get the user's COLUMNS, or none.
if not os.environ.get("PYTEST_XDIST_WORKER"):
    os.environ["KINESTAT_TEST_USER_COLUMNS"] = os.environ.get("COLUMNS", "")
elif os.environ.get("KINESTAT_TEST_USER_COLUMNS"):
    os.environ["COLUMNS"] = os.environ["KINESTAT_TEST_USER_COLUMNS"]
else:
    os.environ.pop("COLUMNS", None)

# A run started with SIGINT ignored (SIG_IGN is inherited: a background job of a shell without
# job control, or a CI runner that ignores it) keeps ignoring Ctrl-C, and so do the processes it
# starts: the tests of Ctrl-C (a real SIGINT, in-process and to a `kinestat view --serve` child)
# would fail. The tests get Python's default handler (a child then starts with the default).
if (threading.current_thread() is threading.main_thread()
        and signal.getsignal(signal.SIGINT) is signal.SIG_IGN):
    signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_xdist_auto_num_workers(config):
    return max(1, min(os.cpu_count() or 1, MAX_WORKERS))


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)
