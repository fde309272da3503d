"""scripts/equal_cost.py's arithmetic, against answers worked out by hand: the relative RMSE,
the reference's noise from its halves and its subtraction, the regions, the cost fit."""
import importlib.util
import os

import numpy as np
import pytest

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
spec = importlib.util.spec_from_file_location(
    "equal_cost", os.path.join(REPO, "scripts", "equal_cost.py"))
equal_cost = importlib.util.module_from_spec(spec)
spec.loader.exec_module(equal_cost)


def grey(values):
    values = np.asarray(values, dtype=np.float64)
    return np.repeat(values[..., None], 3, axis=-1)


def test_luminance_of_grey_is_grey():
    assert equal_cost.luminance(grey([[0.5]]))[0, 0] == pytest.approx(0.5)


def test_relative_rmse_whole_and_region():
    ref = grey(np.full((4, 4), 2.0))
    image = ref.copy()
    image[0, 0] = 4.0  # one pixel off by 2 in the top-left quarter
    s = equal_cost.scores(image, ref, np.zeros((4, 4)), {"tl": (0.0, 0.0, 0.5, 0.5)})
    assert s["whole"]["rel_rmse"] == pytest.approx(np.sqrt(4.0 / 16) / 2.0)
    assert s["tl"]["rel_rmse"] == pytest.approx(np.sqrt(4.0 / 4) / 2.0)
    assert s["tl"]["bias"] == pytest.approx(0.5 / 2.0)


def test_reference_noise_is_subtracted_in_quadrature():
    ref = grey(np.full((2, 2), 1.0))
    image = grey(np.full((2, 2), 1.5))  # MSE 0.25
    var = np.full((2, 2), 0.09)
    s = equal_cost.scores(image, ref, var, {})["whole"]
    assert s["rel_rmse"] == pytest.approx(0.5)
    assert s["rel_rmse_corrected"] == pytest.approx(0.4)
    assert s["reference_rel_noise"] == pytest.approx(0.3)


def test_halves_give_the_variance_of_their_mean():
    # Two halves a, b: mean (a + b) / 2, var of the mean (a - b)^2 / 4.
    a, b = grey([[1.0, 3.0]]), grey([[3.0, 3.0]])
    mean, var = equal_cost.reference_from_halves([a, b])
    assert mean[0, :, 0].tolist() == [2.0, 3.0]
    assert var[0].tolist() == pytest.approx([1.0, 0.0])


def test_halves_of_noise_estimate_its_variance():
    rng = np.random.default_rng(7)
    halves = [grey(rng.normal(1.0, 0.2, size=(200, 200))) for _ in range(4)]
    _, var = equal_cost.reference_from_halves(halves)
    assert var.mean() == pytest.approx(0.04 / 4, rel=0.03)


def test_regions_round_to_pixels():
    rows, cols = equal_cost.region_slices((0.25, 0.5, 0.75, 1.0), 8, 4)
    assert (rows.start, rows.stop, cols.start, cols.stop) == (4, 8, 1, 3)


def test_cost_fit_and_budget_count():
    cost = equal_cost.fit_cost((2, 10), (1.0, 3.0))
    assert cost["per_unit_cpu_s"] == pytest.approx(0.25)
    assert cost["fixed_cpu_s"] == pytest.approx(0.5)
    assert equal_cost.count_for_budget(cost, 30.0) == 118
    assert equal_cost.count_for_budget(cost, 0.1) == 1


def test_power_law_through_measured_points():
    # CPU-s = 0.5 n^1.2 (a cost per pass that grows with the pass count), known at the
    # calibration's larger count and one measured run: the budget's count is exact.
    def cost(n):
        return 0.5 * n ** 1.2
    calibration = {"per_unit_cpu_s": 1.0, "fixed_cpu_s": 0.0, "counts": [2, 10],
                   "render_cpu_s": [cost(2), cost(10)], "points": [[200, cost(200)]]}
    assert equal_cost.predict_count(calibration, cost(400)) == 400
    assert equal_cost.predict_count(calibration, cost(50)) == 50


def test_methods_carry_their_settings():
    assert equal_cost.parse_methods("sppm,pppm:radius_scale=0.5,photons_per_pass=16384,cycles") \
        == ["sppm", "pppm:radius_scale=0.5,photons_per_pass=16384", "cycles"]
    assert equal_cost.parse_methods("sppm:radius_scale=0.5;vcm") == ["sppm:radius_scale=0.5", "vcm"]


def test_region_table_lists_every_region():
    """A scene with several regions (the showcase) gets one column per region and the
    whole image, each with the reference's own noise in the header."""
    score = {"rel_rmse": 0.5, "rel_rmse_corrected": 0.4, "bias": 0.01}
    result = {"regions": {"a": (0, 0, 1, 1), "b": (0, 0, 1, 1)},
              "reference_rel_noise": {"a": 0.1, "b": 0.2, "whole": 0.05},
              "runs": [{"budget": 60.0, "method": "cycles", "render_cpu_s": 59.0,
                        "scores": {"a": score, "b": score, "whole": score}}]}
    lines = equal_cost.region_table(result).split("\n")
    assert lines[0] == ("| budget | method | CPU-s | a (ref. noise 0.100) | b (ref. noise 0.200) "
                        "| whole (ref. noise 0.050) |")
    assert lines[2] == ("| 60 | cycles | 59.0 | 0.500 (0.400), bias +0.010 | "
                        "0.500 (0.400), bias +0.010 | 0.500 (0.400), bias +0.010 |")
