# Shared by the suite: the module under test is the build's (ctest puts <build>/python on
# PYTHONPATH), and `ballpit run` is the build's CLI (BALLPIT_CLI, set by python/CMakeLists.txt).
import os

import pytest


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("BALLPIT_CLI")
    if not path or not os.path.exists(path):
        pytest.skip("BALLPIT_CLI (the build's `ballpit` program) is not set: built with BALLPIT_APP=OFF")
    return path
