"""Where the test suite finds the repository: test files live in sub-folders that mirror the packages."""

import os

#: The repository's root folder (examples/, stdlib/, pyproject.toml).
ROOT_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: The tests folder (golden/, exchange_tools/, the shared helpers).
TESTS_DIR = os.path.dirname(os.path.abspath(__file__))
