"""``robokin ik`` prints every solution; unreachable poses exit with code 1."""

import json

import pytest

pytest.importorskip("typer")

from robokin.cli import main  # noqa: E402


def test_cli_ik_json(capsys):
    assert main(["ik", "ur5", "300", "-200", "400", "180", "0", "45", "--deg", "--mm",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["method"] == "analytic:three_parallel"
    assert len(out["solutions"]) == 8
    assert max(s["position_error_m"] for s in out["solutions"]) < 1e-9


def test_cli_ik_table_and_near(capsys):
    assert main(["ik", "qfmd010", "-0.86", "1.3185", "-0.8351", "0", "0", "50", "--deg",
                 "--near", "30 10 -5 20", "--limits"]) == 0
    out = capsys.readouterr().out
    assert "1 solution(s)" in out


def test_cli_ik_unreachable(capsys):
    assert main(["ik", "ur5", "3", "0", "0", "0", "0", "0"]) == 1
    assert "out of reach" in capsys.readouterr().err


def test_cli_ik_near_not_numbers_names_the_option(capsys):
    code = main(["ik", "ur5", "0.4", "0.1", "0.3", "0", "3.14159", "0", "--near", "a b"])
    assert code == 2
    err = capsys.readouterr().err
    assert "--near" in err and "expected 6 numbers" in err


def test_a_non_finite_coordinate_is_named(capsys):
    from robokin.cli import main

    code = main(["ik", "ur5", "0.3", "nan", "0.2", "0", "0", "0"])
    out, err = capsys.readouterr()
    assert code == 2
    assert "y must be a finite number" in out + err
    assert "Traceback" not in out + err
