"""IMU records and files: frames, the project's CSV, mapped layouts, PSINS text, Parquet, located errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.exceptions import InvalidParameter, SchulerError
from schuler.imu.files import open_record, read_record, write_record
from schuler.imu.readers import CSV_HEADER, ImuFileError, psins_attitude_to_ned
from schuler.imu.record import ImuRecord, axes_matrix, record_info

ARCSEC = math.pi / 180 / 3600


def make_record(n=50, dt=0.01, kind="rate", seed=0):
    rng = np.random.default_rng(seed)
    return ImuRecord(time_s=dt * np.arange(1, n + 1), gyro=rng.normal(size=(n, 3)) * 1e-3,
                     accel=rng.normal(size=(n, 3)) * 1e-2 + [0.0, 0.0, -9.8], kind=kind, sample_interval_s=dt,
                     latitude_rad=0.6, longitude_rad=1.9, height_m=380.0, initial_attitude_rad=(0.0, 0.01, 1.5),
                     gravity_m_s2=9.78, source="test")


def write_lines(path, lines, encoding="utf-8", bom=b""):
    path.write_bytes(bom + ("\n".join(lines) + "\n").encode(encoding))
    return path


def csv_lines(n=20, dt=0.01, mutate=None):
    rows = [",".join(CSV_HEADER)]
    for k in range(1, n + 1):
        values = [k * dt, 1e-4, -2e-4, 3e-4, 0.01, -0.02, -9.8]
        if mutate:
            values = mutate(k, values)
        rows.append(",".join(str(v) for v in values))
    return rows


@pytest.mark.parametrize("axes, vector, expected", [
    ("FRD", [1, 2, 3], [1, 2, 3]),
    ("RFU", [1, 2, 3], [2, 1, -3]),   # PSINS X right, Y forward, Z up
    ("FLU", [1, 2, 3], [1, -2, -3]),  # ROS-style x forward, y left, z up
    ("RBD", [1, 2, 3], [-2, 1, 3]),
])
def test_axes_matrix_maps_file_axes_to_forward_right_down(axes, vector, expected):
    assert axes_matrix(axes) @ np.array(vector, float) == pytest.approx(expected)
    assert np.linalg.det(axes_matrix(axes)) == pytest.approx(1.0)


@pytest.mark.parametrize("axes, message", [("FRU", "left-handed"), ("FFD", "same body axis"), ("XYZ", "three letters")])
def test_axes_matrix_refuses_bad_triads(axes, message):
    with pytest.raises(InvalidParameter, match=message):
        axes_matrix(axes)


def test_psins_attitude_converts_yaw_to_heading_and_keeps_small_tilts():
    # PSINS yaw is positive towards west: yaw -90.6 deg is heading 90.6 deg (forward axis east)
    roll, pitch, heading = psins_attitude_to_ned(0.0, 0.0, -90.6)
    assert (roll, pitch, math.degrees(heading)) == pytest.approx((0.0, 0.0, 90.6))
    # nose up is positive pitch in both conventions; right wing down positive roll in both
    roll, pitch, heading = psins_attitude_to_ned(2.0, 0.0, 0.0)
    assert math.degrees(pitch) == pytest.approx(2.0) and roll == pytest.approx(0.0, abs=1e-12)
    roll, pitch, heading = psins_attitude_to_ned(0.0, 3.0, 0.0)
    assert math.degrees(roll) == pytest.approx(3.0) and pitch == pytest.approx(0.0, abs=1e-12)


def test_record_views_rates_and_increments_consistently():
    record = make_record(kind="increment")
    assert record.gyro_rate_rad_s == pytest.approx(record.gyro / 0.01)
    assert record.accel_increment_m_s is record.accel
    info = record_info(record)
    assert info.samples == 50 and info.duration_s == pytest.approx(0.5)
    assert info.earth_rate_down_rad_s == pytest.approx(-7.292115e-5 * math.sin(0.6))
    assert "mean gyro" in str(info)


def test_csv_round_trip(tmp_path):
    record = make_record()
    back = read_record(write_record(record, tmp_path / "r.csv"))
    assert back.kind == "rate" and back.sample_interval_s == pytest.approx(0.01)
    assert np.array_equal(back.gyro, record.gyro) and np.array_equal(back.accel, record.accel)


def test_parquet_round_trip_keeps_metadata_and_streams(tmp_path):
    record = make_record(n=1000, kind="increment")
    path = write_record(record, tmp_path / "r.parquet")
    back = read_record(path)
    assert np.array_equal(back.gyro, record.gyro) and back.kind == "increment"
    assert (back.latitude_rad, back.height_m, back.gravity_m_s2) == (0.6, 380.0, 9.78)
    assert back.initial_attitude_rad == record.initial_attitude_rad
    chunks = list(open_record(path).chunks(rows=300))
    assert [c[0].size for c in chunks] == [300, 300, 300, 100]


def test_csv_mapping_converts_deg_per_s_and_g(tmp_path):
    lines = ["time_ms;wx;wy;wz;ax;ay;az"] + [f"{10 * k};1;2;3;0;0.5;-1" for k in range(1, 11)]
    path = write_lines(tmp_path / "other.txt", lines)
    record = read_record(path, delimiter=";", columns={"time": "time_ms", "gyro_x": "wx", "gyro_y": "wy",
                                                       "gyro_z": "wz", "accel_x": "ax", "accel_y": "ay",
                                                       "accel_z": "az"},
                         units={"time": "ms", **{f"gyro_{a}": "deg/s" for a in "xyz"},
                                **{f"accel_{a}": "g" for a in "xyz"}}, axes="FLU")
    assert record.sample_interval_s == pytest.approx(0.01)
    # FLU -> FRD: y and z change sign
    assert record.gyro[0] == pytest.approx(np.radians([1.0, -2.0, -3.0]))
    assert record.accel[0] == pytest.approx([0.0, -0.5 * 9.80665, 9.80665])


def test_csv_increments_in_deg_and_m_per_s(tmp_path):
    lines = [",".join(CSV_HEADER)] + [f"{0.1 * k},0.001,0,0,0,0,-0.98" for k in range(1, 6)]
    path = write_lines(tmp_path / "inc.csv", lines)
    record = read_record(path, kind="increment", units={"gyro_x": "deg", "gyro_y": "deg", "gyro_z": "deg"})
    assert record.kind == "increment"
    assert record.gyro_rate_rad_s[0, 0] == pytest.approx(math.radians(0.001) / 0.1)
    assert record.accel_m_s2[0, 2] == pytest.approx(-9.8)


@pytest.mark.parametrize("mutate, line, column, message", [
    (lambda k, v: [0.05 if k == 7 else v[0]] + v[1:], 8, 1, "time does not increase"),
    (lambda k, v: [v[0] + (0.5 if k >= 12 else 0.0)] + v[1:], 13, 1, "gap"),
    (lambda k, v: v[:3] + (["nan"] if k == 5 else [v[3]]) + v[4:], 6, 4, "empty or non-finite"),
    (lambda k, v: v[:5] + (["abc"] if k == 9 else [v[5]]) + v[6:], 10, 6, "not a number"),
    (lambda k, v: v[:6] + ([""] if k == 3 else [v[6]]), 4, 7, "empty or non-finite"),
])
def test_csv_errors_name_file_line_and_column(tmp_path, mutate, line, column, message):
    path = write_lines(tmp_path / "bad.csv", csv_lines(mutate=mutate))
    with pytest.raises(ImuFileError, match=message) as error:
        read_record(path)
    assert (error.value.line, error.value.column) == (line, column)
    assert str(error.value).startswith(f"bad.csv, line {line}, column {column}")


def test_csv_wrong_units_in_header(tmp_path):
    lines = csv_lines()
    lines[0] = lines[0].replace("gyro_y_rad_s", "gyro_y_deg_s")
    with pytest.raises(ImuFileError, match="wrong units.*gyro_y_deg_s") as error:
        read_record(write_lines(tmp_path / "h.csv", lines))
    assert (error.value.line, error.value.column) == (1, 3)


def test_csv_accelerometer_in_g_declared_as_si_is_refused(tmp_path):
    lines = csv_lines(mutate=lambda k, v: v[:6] + [-1.0])
    with pytest.raises(ImuFileError, match="looks like g"):
        read_record(write_lines(tmp_path / "g.csv", lines))
    assert read_record(tmp_path / "g.csv", check_units=False).accel[0, 2] == -1.0


def test_mapping_unit_of_the_wrong_kind_is_refused(tmp_path):
    path = write_lines(tmp_path / "r.csv", csv_lines())
    with pytest.raises(InvalidParameter, match="units.gyro_x.*not an angular rate"):
        read_record(path, units={"gyro_x": "m/s"})
    with pytest.raises(InvalidParameter, match="unknown channel 'gyro_w'"):
        read_record(path, columns={"gyro_w": "x"})


@pytest.mark.parametrize("encoding, bom", [("utf-8", b"\xef\xbb\xbf"), ("utf-16-le", b"\xff\xfe"),
                                           ("utf-16-be", b"\xfe\xff"), ("latin-1", b"")])
def test_encodings_are_read(tmp_path, encoding, bom):
    lines = ["# recorded at 20 °C, µ-strain free"] + csv_lines()
    record = read_record(write_lines(tmp_path / "e.csv", lines, encoding=encoding, bom=bom))
    assert record.samples == 20


def test_binary_or_unmarked_utf16_is_one_clear_error(tmp_path):
    path = write_lines(tmp_path / "u16.csv", csv_lines(), encoding="utf-16-le")
    with pytest.raises(ImuFileError, match="NUL bytes"):
        read_record(path)


def test_memory_estimate_refuses_before_reading(tmp_path):
    path = write_lines(tmp_path / "big.csv", csv_lines(n=2000))
    source = open_record(path)
    assert 1800 < source.estimated_samples < 2200
    with pytest.raises(ImuFileError, match="GB in memory"):
        source.read(max_memory_bytes=10_000)


def test_missing_file_and_unknown_suffix_options(tmp_path):
    with pytest.raises(ImuFileError, match="no such file"):
        open_record(tmp_path / "none.csv")
    path = write_record(make_record(), tmp_path / "r.parquet")
    with pytest.raises(InvalidParameter, match="CSV files only"):
        open_record(path, kind="rate")
    with pytest.raises(SchulerError):
        write_record(make_record(), tmp_path / "r.txt")


PSINS_HEADER = [
    "% PSINS-format SIMU log file.",
    "% 2nd line: lat lon h t0 ts(ms) g",
    "",
    "1.0 2.0 -90.6 0 0 0",
    "34.246048 108.909664 380 0 10 9.780327",
    "0.1 0.1 0.1 125 125 125",
]


def test_psins_counts_scale_with_the_files_g_and_axes_convert(tmp_path):
    counts = ["3 -2 7 1 2 80", "1 0 -1 0 0 81", "0 0 0 0 0 80"]
    record = read_record(write_lines(tmp_path / "s.imu", PSINS_HEADER + counts))
    assert record.kind == "increment" and record.sample_interval_s == 0.01
    assert record.time_s == pytest.approx([0.01, 0.02, 0.03])   # increments end at t0 + k ts
    # X right = 3, Y forward = -2, Z up = 7 counts of 0.1 arcsec -> x fwd -2, y right 3, z down -7
    assert record.gyro[0] == pytest.approx(np.array([-2.0, 3.0, -7.0]) * 0.1 * ARCSEC)
    # 125 ug*s per count times the file's g (9.780327), not 9.80665
    assert record.accel[0] == pytest.approx(np.array([2.0, 1.0, -80.0]) * 125e-6 * 9.780327)
    assert record.gravity_m_s2 == 9.780327
    assert math.degrees(record.latitude_rad) == pytest.approx(34.246048)
    assert math.degrees(record.initial_attitude_rad[2]) == pytest.approx(90.6, abs=0.05)


def test_psins_errors_are_located(tmp_path):
    bad_header = PSINS_HEADER[:4] + ["34.2 108.9 380 0 10"] + PSINS_HEADER[5:]
    with pytest.raises(ImuFileError, match="line 5: header line 2 must hold 6 finite numbers"):
        read_record(write_lines(tmp_path / "h.imu", bad_header + ["0 0 0 0 0 80"]))
    with pytest.raises(ImuFileError, match="line 8, column 3.*not a number"):
        read_record(write_lines(tmp_path / "d.imu", PSINS_HEADER + ["0 0 0 0 0 80", "0 0 x 0 0 80"]))
