"""Heatmap metrics against hand-computed values on tiny maps."""

import numpy as np
import pytest
import torch
from torchmetrics.classification import BinaryAveragePrecision

from vnrrt.data.targets import dilate as dilate_numpy
from vnrrt.model.metrics import (
    MaskedAveragePrecision,
    MassNear,
    PixelAveragePrecision,
    VertexRecall,
    dilate,
    heatmap_metric_set,
    metric_collection,
)


def mask(shape, *cells):
    """(1, H, W) bool with the given (x, y) cells set."""
    m = torch.zeros((1, *shape), dtype=torch.bool)
    for x, y in cells:
        m[0, y, x] = True
    return m


@pytest.mark.parametrize("radius", [0, 1, 1.5, 2, 3.2])
def test_torch_dilation_matches_opencv(radius):
    rng = np.random.default_rng(3)
    m = rng.random((2, 17, 23)) < 0.03
    got = dilate(torch.from_numpy(m), radius).numpy()
    want = np.stack([dilate_numpy(x, radius) for x in m])
    np.testing.assert_array_equal(got, want)


def test_pixel_ap_hand_computed_and_equal_to_torchmetrics():
    preds = torch.tensor([[[0.9, 0.8], [0.3, 0.1]]])  # ranked: pos, neg, pos, neg
    target = torch.tensor([[[1, 0], [1, 0]]])
    # recall 1/2 at precision 1, then recall 1 at precision 2/3
    assert PixelAveragePrecision(101)(preds, target) == pytest.approx(0.5 + 0.5 * 2 / 3)
    rng = torch.Generator().manual_seed(0)
    preds = torch.rand(3, 20, 20, generator=rng) ** 3
    target = (torch.rand(3, 20, 20, generator=rng) < preds).long()
    for t in (2, 11, 101):
        want = BinaryAveragePrecision(thresholds=t)(preds.flatten(), target.flatten())
        assert PixelAveragePrecision(t)(preds, target) == pytest.approx(float(want), abs=1e-6)
    preds[0, 0, :5] = torch.tensor([0.0, 0.25, 0.5, 0.75, 1.0])  # exactly on thresholds
    want = BinaryAveragePrecision(thresholds=5)(preds.flatten(), target.flatten())
    assert PixelAveragePrecision(5)(preds, target) == pytest.approx(float(want), abs=1e-6)


def test_vertex_recall_hand_computed():
    vertices = mask((5, 5), (0, 0), (4, 4))
    preds = torch.zeros(1, 5, 5)
    preds[0, 1, 1] = 0.7  # (x=1, y=1): sqrt(2) from (0, 0), far from (4, 4)
    assert VertexRecall(radius=1, tau=0.5)(preds, vertices=vertices) == 0.0  # sqrt 2 > 1
    assert VertexRecall(radius=1.5, tau=0.5)(preds, vertices=vertices) == 0.5
    assert VertexRecall(radius=1.5, tau=0.8)(preds, vertices=vertices) == 0.0  # 0.7 < tau
    preds[0, 4, 4] = 0.5  # exactly tau counts
    assert VertexRecall(radius=0, tau=0.5)(preds, vertices=vertices) == 0.5


def test_vertex_recall_pools_vertices_over_images():
    metric = VertexRecall(radius=0, tau=0.5)
    metric.update(torch.ones(1, 4, 4), vertices=mask((4, 4), (0, 0)))  # 1 of 1
    metric.update(torch.zeros(1, 4, 4), vertices=mask((4, 4), (1, 1), (2, 2), (3, 3)))  # 0 of 3
    assert metric.compute() == pytest.approx(0.25)


def test_mass_near_hand_computed():
    path = mask((4, 4), (0, 0))
    uniform = torch.full((1, 4, 4), 0.3)
    assert MassNear(0, "path")(uniform, path=path) == pytest.approx(1 / 16)
    assert MassNear(1, "path")(uniform, path=path) == pytest.approx(3 / 16)  # clipped plus
    assert MassNear(1, "path", uniform=True)(uniform * 0, path=path) == pytest.approx(3 / 16)
    peaked = torch.zeros(1, 4, 4)
    peaked[0, 0, 0], peaked[0, 3, 3] = 0.6, 0.2
    assert MassNear(0, "path")(peaked, path=path) == pytest.approx(0.75)
    verts = mask((4, 4), (3, 3))
    assert MassNear(0, "vertices")(peaked, path=path, vertices=verts) == pytest.approx(0.25)


def test_masked_mass_near_zeroes_low_probabilities_and_falls_back_to_uniform():
    verts = mask((4, 4), (0, 0))
    preds = torch.full((2, 4, 4), 0.1)
    preds[0, 0, 0], preds[0, 3, 3] = 0.9, 0.6  # image 0: 0.9 of 1.5 above tau near the vertex
    metric = MassNear(0, "vertices", tau=0.5)
    metric.update(preds, vertices=verts.expand(2, 4, 4))  # image 1: nothing >= tau: uniform
    assert metric.compute() == pytest.approx((0.9 / 1.5 + 1 / 16) / 2)


def test_mass_near_averages_over_images():
    metric = MassNear(0, "path")
    preds = torch.zeros(2, 2, 2)
    preds[0, 0, 0] = 1.0  # all mass on the path
    preds[1] = 1.0  # a quarter of the mass on the path
    path = torch.zeros(2, 2, 2, dtype=torch.bool)
    path[:, 0, 0] = True
    metric.update(preds, path=path)
    assert metric.compute() == pytest.approx((1.0 + 0.25) / 2)


def test_collection_keys_and_perfect_prediction():
    metrics = metric_collection(
        radius=0, tau=0.5, ap_radius=1.0, endpoint_radius=3.0, taus=(0.5, 0.9, 0.99)
    ).clone(prefix="val/")
    target = mask((6, 6), (1, 1), (4, 2))
    preds = target.float() * 0.9  # (1, 6, 6)
    ends = mask((6, 6), (1, 1))
    interior = mask((6, 6), (4, 2))
    out = metrics(preds=preds, target=target.to(torch.uint8), vertices=target, path=target,
                  interior=interior, endpoints=ends)  # fmt: skip
    masked = [f"mass_near_interior_tau{t}" for t in ("0_5", "0_9", "0_99")]
    assert set(out) == {f"val/{k}" for k in ("ap", "f1", "vertex_recall", "mass_near_path",
                        "mass_near_path_uniform", "mass_near_vertex", "interior_recall",
                        "mass_near_vertex_uniform", "mass_near_vertex_masked", "interior_ap",
                        "path_ap", "mass_near_interior", "mass_near_interior_uniform",
                        "mass_on_endpoints", *masked)}  # fmt: skip
    assert out["val/ap"] == pytest.approx(1.0) and out["val/f1"] == pytest.approx(1.0)
    assert out["val/vertex_recall"] == 1.0 and out["val/mass_near_vertex"] == pytest.approx(1.0)
    assert out["val/mass_near_vertex_uniform"] == pytest.approx(2 / 36)


def interior_case():
    """A 20x20 image: start (1, 1) and goal (18, 18) carry most of the heatmap's mass, one
    interior vertex (10, 4) a little, another (4, 12) none; one false peak at (15, 5)."""
    ends, interior = mask((20, 20), (1, 1), (18, 18)), mask((20, 20), (10, 4), (4, 12))
    preds = torch.zeros(1, 20, 20)
    preds[0, 1, 1] = preds[0, 18, 18] = 0.95  # the endpoints
    preds[0, 4, 10] = 0.6  # found interior vertex
    preds[0, 5, 15] = 0.7  # a false positive, ranked above the true one
    return preds, {"endpoints": ends, "interior": interior, "vertices": ends | interior}


def test_interior_metrics_leave_the_endpoints_out():
    preds, masks = interior_case()
    m = heatmap_metric_set(radius=0, tau=0.5, ap_radius=1.0, endpoint_radius=0, taus=(0.5, 0.9))
    out = {k: float(v(preds, path=masks["vertices"], **masks)) for k, v in m.items()}
    assert out["vertex_recall"] == pytest.approx(3 / 4)  # the endpoints count here ...
    assert out["interior_recall"] == pytest.approx(1 / 2)  # ... not here
    total = 0.95 * 2 + 0.6 + 0.7
    assert out["mass_on_endpoints"] == pytest.approx(1.9 / total)
    assert out["mass_near_interior"] == pytest.approx(0.6 / total)
    assert out["mass_near_interior_uniform"] == pytest.approx(2 / 400)
    assert out["mass_near_interior_tau0_5"] == pytest.approx(0.6 / total)  # all kept at 0.5
    assert out["mass_near_interior_tau0_9"] == pytest.approx(0.0)  # only the endpoints kept
    # AP over the interior positives, the endpoint pixels ignored: precision 0 at the false
    # peak's level (0.7), 1/2 once the true one (0.6) is in (recall 1/2); the unfound one
    # only at threshold 0, where all 398 kept pixels count (precision 2/398).
    ap = MaskedAveragePrecision("interior", 0.0, "endpoints", 0.0)(preds, **masks)
    assert float(ap) == pytest.approx(0.5 * 0.5 + 0.5 * 2 / 398)
    with_ends = MaskedAveragePrecision("vertices", 0.0)(preds, **masks)
    assert float(with_ends) > float(ap)  # the confident endpoints raise the plain AP


def test_masked_ap_dilates_positives():
    preds, masks = interior_case()
    shifted = torch.zeros_like(preds)
    shifted[0, 4, 11] = 0.9  # one pixel right of the interior vertex (10, 4)
    strict = MaskedAveragePrecision("interior", 0.0)(shifted, **masks)
    loose = MaskedAveragePrecision("interior", 1.0)(shifted, **masks)
    assert float(strict) == pytest.approx(2 / 400)  # only at threshold 0: all pixels
    assert float(loose) == pytest.approx(1 / 10 + 0.9 * 10 / 400)  # 1 of 10 found, at 0.9
