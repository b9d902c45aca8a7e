"""Reading callgrind's files: the total, and the instructions each library ran (exclusive
costs, which add up to the total), on a file written by hand in callgrind's format."""

from __future__ import annotations

import pytest

from wire_fmu.bench import callgrind_file

# Two objects, names given once and then by id, relative positions, a call whose
# inclusive cost line must not count again, and code in no object file (???).
_FILE = """# callgrind format
version: 1
creator: callgrind-3.19.0
part: 1
positions: line
events: Ir
summary: 0

ob=(1) /usr/lib/libpython3.11.so.1.0
fl=(1) ceval.c
fn=(1) _PyEval_EvalFrameDefault
10 100
+2 50
cob=(2) /usr/lib/x86_64-linux-gnu/libc.so.6
cfi=(2) malloc.c
cfn=(2) malloc
calls=3 20
* 30
-1 5

ob=(2)
fl=(2)
fn=(2)
20 30

ob=(3) ???
fl=(3) ???
fn=(3) 0x0000000012345678
0 40
cob=(4) /site-packages/numba/core/runtime/_nrt_python.so
cfi=(4) nrt.cpp
cfn=(4) NRT_MemInfo_alloc_aligned
calls=7 0
* 14
cfn=(2)
calls=2 20
* 0
cfn=(4)
calls=5 0
* 10

ob=(4)
fl=(4)
fn=(4)
0 24

ob=(1)
fl=(1)
fn=(1)
12 25

totals: 274
"""


@pytest.fixture
def dump(tmp_path):
    path = tmp_path / "callgrind.out.1"
    path.write_text(_FILE)
    return path


def test_each_object_gets_its_own_lines_and_not_the_calls_it_makes(dump):
    by_object = callgrind_file.instructions_by_object(dump)
    assert by_object == {
        "/usr/lib/libpython3.11.so.1.0": 100 + 50 + 5 + 25,  # the call's 30 is malloc's
        "/usr/lib/x86_64-linux-gnu/libc.so.6": 30,
        "???": 40,
        "/site-packages/numba/core/runtime/_nrt_python.so": 24,
    }
    assert sum(by_object.values()) == callgrind_file.callgrind_total(dump) == 274


def test_libraries_are_grouped_most_first(dump):
    assert callgrind_file.instructions_by_library(dump) == {
        "the Python interpreter": 180,
        "the compiled kernels (numba's machine code)": 40,
        "the C library (malloc, free, memset, memcpy)": 30,
        "numba's runtime and dispatch": 24,
    }


def test_calls_into_a_function_are_counted_by_its_name_given_once(dump):
    # numba's allocator called 7 and then 5 times (named by id the second time); the
    # calls of malloc in between are not its
    assert callgrind_file.calls_to(dump, "NRT_MemInfo_alloc") == 12
    assert callgrind_file.calls_to(dump, "malloc") == 3 + 2
    assert callgrind_file.calls_to(dump, "free") == 0


@pytest.mark.parametrize(
    ("obj", "group"),
    [
        ("/tmp/wire_fmu_fmu_x/binaries/linux64/BlockTrain.so", "the FMU binaries"),
        (
            "/venv/site-packages/numba/core/runtime/_nrt_python.cpython-311.so",
            "numba's runtime and dispatch",
        ),
        ("/venv/site-packages/numpy/_core/_multiarray_umath.cpython-311.so", "numpy"),
        ("/usr/lib/x86_64-linux-gnu/libffi.so.8.1.2", "ctypes and libffi (the FMI calls)"),
        ("/usr/lib/x86_64-linux-gnu/libm.so.6", "libm"),
        ("/python3.11/lib-dynload/_struct.cpython-311.so", callgrind_file.OTHER),
    ],
)
def test_object_files_are_put_in_their_library(obj, group):
    assert callgrind_file.library_of(obj) == group


@pytest.mark.parametrize(
    ("header", "end"),
    [
        ("summary: 0", "totals: 123456789"),  # a dump made while the program runs
        ("summary: 123456789", ""),  # a file with its summary only
    ],
)
def test_the_total_is_read_from_a_callgrind_file(tmp_path, header, end):
    path = tmp_path / "callgrind.out.1"
    path.write_text(
        f"# callgrind format\nversion: 1\nevents: Ir\n{header}\nfn=(1) main\n3 5\n{end}\n"
    )
    assert callgrind_file.callgrind_total(path) == 123456789


def test_a_file_without_a_total_is_refused_naming_it(tmp_path):
    path = tmp_path / "not_callgrind.txt"
    path.write_text("hello\n")
    with pytest.raises(ValueError, match="not_callgrind.txt"):
        callgrind_file.callgrind_total(path)


# libffi calls into an FMU binary twice (the second call's object named by its id), the
# binary calls into the interpreter and within itself; the interpreter calls libffi.
_CROSSINGS = """# callgrind format
version: 1
positions: line
events: Ir
summary: 0

ob=(1) /usr/lib/x86_64-linux-gnu/libffi.so.8
fl=(1) unix64.S
fn=(1) ffi_call_unix64
1 10
cob=(2) /tmp/wire_fmu_x/binaries/linux64/Rope.so
cfi=(2) fmi2Functions.cpp
cfn=(2) fmi2DoStep
calls=1 5
* 700
cob=(2)
cfn=(3) fmi2GetReal
calls=1 9
* 80
cfn=(4) ffi_prep
calls=1 3
* 6

ob=(2)
fl=(2)
fn=(2)
5 20
cob=(3) /usr/lib/libpython3.11.so.1.0
cfi=(3) ceval.c
cfn=(5) PyObject_Call
calls=1 1
* 600
cfn=(3)
calls=1 9
* 80
fn=(3)
9 80

ob=(1)
fl=(1)
fn=(4)
3 6

ob=(3)
fl=(3)
fn=(5)
1 600

totals: 716
"""


def test_calls_into_the_fmus_count_everything_they_ran_once(tmp_path):
    path = tmp_path / "callgrind.out.1"
    path.write_text(_CROSSINGS)
    # fmi2DoStep (its 20, the interpreter's 600, GetReal's 80 inside it) and a GetReal;
    # not the binary's call to itself, nor libffi's to itself
    assert callgrind_file.instructions_called_into(path, ("/binaries/",)) == 700 + 80
    assert callgrind_file.instructions_called_into(path, ("libpython",)) == 600
    assert callgrind_file.instructions_called_into(path, ("libm.so",)) == 0
    assert sum(callgrind_file.instructions_by_object(path).values()) == 716
