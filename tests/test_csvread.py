"""The CSV reader's one-call path for plain files reads what its general, line-by-line path reads."""
from __future__ import annotations

import numpy as np
import pytest

from frictionlab.core.errors import DatasetError
from frictionlab.io import csvread

PLAIN = [
    "t,v\n0,1\n1,2\n",
    "# a comment line\nt,v\n0,1.5e-3  # trailing comment\n\n1, -2.25\n",
    " t , v ,w\r\n0.1,2,3\r\n4,5,6e+300\r\n",
    "t\n1\n2\n3\n",
    "t,x,mu\n11093.154,3515.946,0.498358\n11093.29,3516.371,0.497466\n",
    "t,v\n1_000,0x\n",  # 0x is no number: the general path names it
    "t,v\n1,2\n3\n",  # a short row: the general path names it
    "t,v\n1,2,3\n",  # a long row
    "t,v\n1,nan\n",
    "t,t\n1,2\n",
    "t,\n1,2\n",
    "t;v\n1;2\n",
    "t,v\n",
    '"t","v"\n"1", "2"\n',
]


def _read(text, plain: bool):
    if not plain:
        saved = csvread._plain
        csvread._plain = lambda _text: None
    try:
        return csvread.read_csv("data.csv", text=text)
    except DatasetError as exc:
        return str(exc)
    finally:
        if not plain:
            csvread._plain = saved


@pytest.mark.parametrize("text", PLAIN)
def test_the_one_call_path_reads_what_the_line_by_line_path_reads(text):
    fast, general = _read(text, True), _read(text, False)
    if isinstance(general, str):
        assert fast == general
        return
    assert list(fast) == list(general)
    for name in general:
        assert fast[name].dtype == general[name].dtype and fast[name].flags.c_contiguous
        np.testing.assert_array_equal(fast[name], general[name])


def test_plain_files_take_the_one_call_path_and_others_do_not():
    assert csvread._plain("# c\nt,v\n0,1  # c\n1,2\n") is not None
    for text in ('"t",v\n0,1\n', "t,v\n0\n", "t,v\n0,x\n", "t,v\n0,inf\n", "t,v\n"):
        assert csvread._plain(text) is None


@pytest.mark.parametrize("text, line", [('t,omega,theta\n"\r"', 2), ('t,a\n1,"2\n3",4\n5,6', 2), ('t,"a\n1",2\n3,4', 1)])
def test_a_quoted_cell_left_open_at_the_end_of_its_line_is_named(text, line):
    """A line ending (\\n, \\r) inside quotes would let one row take the next line; it is refused at its line."""
    with pytest.raises(DatasetError, match=f"data.csv: CSV does not parse: line {line}: a quoted cell is not closed"):
        csvread.read_csv("data.csv", text=text)
