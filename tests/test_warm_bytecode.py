"""The set-up's bytecode step (tests/warm_bytecode.py) names the modules the sources
import, wherever the import statement is."""

from tests.warm_bytecode import imported_modules, project_imports, third_party

SOURCE = """
import numpy as np
import scipy.integrate
from pyarrow import parquet, Table
from . import sibling
from .sub import thing


def later():
    import rerun as rr
    from matplotlib.figure import Figure
"""


def test_import_statements_anywhere_name_their_modules_and_what_they_take():
    assert imported_modules(SOURCE) == {
        "numpy",
        "scipy.integrate",
        "pyarrow",
        "pyarrow.parquet",
        "pyarrow.Table",
        "rerun",
        "matplotlib.figure",
        "matplotlib.figure.Figure",
    }


def test_the_standard_library_and_the_projects_own_modules_are_left_out():
    names = {"os.path", "json", "harness.cli", "reference.core.aot", "tests.conftest"}
    assert third_party(names | {"numpy", "scipy.integrate"}) == ["numpy", "scipy.integrate"]


def test_the_modules_the_command_line_imports_where_it_uses_them_are_named():
    # harness imports these inside the functions that use them (start-up, performance.md)
    assert {"rerun", "pandas", "matplotlib.pyplot", "pyarrow.parquet"} <= set(project_imports())
