"""A recording's header: units in the column names, a byte-order mark, and the --columns line for a miss."""

import warnings

import numpy as np
import pytest

from ddmm.population.stimuli._csv_header import split_unit
from ddmm.population.stimuli.recordings import from_csv

ROWS = "".join(f"{k},0,0,{min(k, 2000)}\n" for k in range(0, 2500))  # 1 kHz in ms, F_Z up to 2000 mN


def read(tmp_path, header, **options):
    path = tmp_path / "plate.csv"
    path.write_text(header + "\n" + ROWS, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return from_csv(path, conditioning=None, **options)


@pytest.mark.parametrize("header", ["Time (ms),Fx (mN),Fy (mN),Fz (mN)", "time [ms],fx [mN],fy [mN],fz [mN]",
                                    "\ufeffTime (ms),Fx (mN),Fy (mN),Fz (mN)"])
def test_units_in_the_header_are_read_without_options(tmp_path, header):
    scene = read(tmp_path, header)
    assert scene.fs == 1000.0 and scene.fz[-1] == pytest.approx(2.0)


def test_a_byte_order_mark_is_not_part_of_the_first_column(tmp_path):
    scene = read(tmp_path, "\ufefftime,fx,fy,fz", time_scale=1e-3, units="mN")
    assert scene.fz[-1] == pytest.approx(2.0)


def test_options_that_contradict_the_header_are_refused_by_name(tmp_path):
    with pytest.raises(ValueError, match=r"units='N' \(--units N\) but column 'Fz \(mN\)' is in mN"):
        read(tmp_path, "Time (ms),Fx (mN),Fy (mN),Fz (mN)", units="N")
    with pytest.raises(ValueError, match=r"time_scale=1 \(--time-scale 1\) but column 'Time \(ms\)' is in ms"):
        read(tmp_path, "Time (ms),Fx (mN),Fy (mN),Fz (mN)", time_scale=1.0)
    with pytest.raises(ValueError, match=r"column 'Fx \(V\)' is in 'V', not a force unit"):
        read(tmp_path, "Time (ms),Fx (V),Fy (V),Fz (V)")
    with pytest.raises(ValueError, match="the force columns name different units"):
        read(tmp_path, "Time (ms),Fx (N),Fy (mN),Fz (mN)")


def test_a_header_that_does_not_match_gets_the_columns_line_that_reads_it(tmp_path):
    with pytest.raises(ValueError, match=r"header: Zeit,Kraft X,Kraft Y,Kraft Z; read it with columns=.*"
                                         r"\(--columns 'time=Zeit,fx=Kraft X,fy=Kraft Y,fz=Kraft Z'\)"):
        read(tmp_path, "Zeit,Kraft X,Kraft Y,Kraft Z")
    with pytest.raises(ValueError, match=r"no column 'time' \(for time\), 'fz' \(for fz\).*--columns time=t,fz=force_z"):
        read(tmp_path, "t,fx,fy,force_z")
    scene = read(tmp_path, "Zeit,Kraft X,Kraft Y,Kraft Z", time_scale=1e-3, units="mN",
                 columns={"time": "Zeit", "fx": "Kraft X", "fy": "Kraft Y", "fz": "Kraft Z"})
    assert np.isclose(scene.fz[-1], 2.0)


def test_split_unit():
    assert split_unit(" Fz (mN) ") == ("Fz", "mN") and split_unit("Fz[N]") == ("Fz", "N")
    assert split_unit("(s)") == ("(s)", None) and split_unit("Fz ()") == ("Fz ()", None)
