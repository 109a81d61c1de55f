"""The equations of motion as data: what a registry entry must carry, that every place reads the
registry, and that a third equation is one entry plus its physics."""

import dataclasses
import math

import numpy as np
import pytest

import spinviz
from spinviz import presentation
from spinviz.inputs.scene_spec import parse_scene
from spinviz.physics import bodies as B
from spinviz.physics import models as M
from spinviz.physics.equations import free_rate


def test_every_registered_model_carries_what_an_entry_must():
    """An entry names its equations and says what it predicts; its rate is the whole of its
    terms (free = 1) and splits into the free motion and its radiation part (free = 0) exactly;
    a model that brakes has a radiation part, one that does not has none; the optional parts are
    whole (a line law with a formula and an equation, type labels for every class)."""
    rng = np.random.default_rng(7)
    J, g = (1.0, 0.8, 0.55), (0.5, 0.3, 0.8)
    for name in M.names():
        m = M.get(name)
        assert m.name == name and m.equations and m.summary
        for w in rng.normal(size=(5, 3)):
            whole = np.array(m.rate(*w, J, g))
            parts = np.array(m.radiation(*w, J, g)) + np.array(free_rate(*w, J, g))
            assert np.allclose(whole, parts, rtol=1e-12, atol=1e-15)
            assert (np.linalg.norm(m.radiation(*w, J, g)) > 0) == m.brakes
        if m.line is not None:
            assert m.line.formula.startswith("P ∝") and m.line.equation.startswith("(")
        if m.type_labels is not None:
            assert set(m.type_labels) == set(M.CLASSES)


def test_presentation_covers_every_registered_model_and_tells_them_apart():
    """Every model has its own colour, a line for the plots and heading and subtitle words in
    both registers."""
    colors = set()
    for name in M.names():
        assert name in presentation.STYLES, f"presentation.STYLES has no row for {name!r}"
        st = presentation.STYLES[name]
        assert set(st.heading) == set(st.subtitle) == {"outreach", "physics"}
        colors.add(st.color)
    assert len(colors) == len(M.names())


def test_the_schema_and_the_kernels_read_the_registry():
    """The schema's model names are the registry's, in its order (the same message in a scene and
    in Python); the compiled kernels know a model by its kernel id."""
    with pytest.raises(spinviz.SpecError, match=f"unknown value 'schott'; valid: {', '.join(M.names())}"):
        spinviz.simulate(B.symmetric_top(0.3, 0.7), "schott", [0.0, 0.05, 0.3], t_end=1.0, samples=2)
    assert [M.get(n).kernel_id for n in M.names()] == [1, 2, 0]
    with pytest.raises(ValueError, match="already registered"):
        M.register(M.REDUCED)
    with pytest.raises(ValueError, match="type_labels lacks"):
        M.Model(name="half", equations="(0)", summary="x", terms=M.REDUCED.terms, type_labels={"residual": "R"})


# --- a third equation: one entry plus its physics --------------------------------------------
def _drag_terms(w1, w2, w3, J, g, free):
    """A toy equation: the free top plus an isotropic drag -|g|^2 |Omega|^2 Omega / J1, whose
    spin on a sphere falls as |Omega|^2 = |Omega0|^2 / (1 + 2 |g|^2 |Omega0|^2 t / J1) -- the
    law (3.9) gives the perpendicular spin; plain arithmetic, so heyoka builds it as it is."""
    J1, J2, J3 = J
    k = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) * (w1 * w1 + w2 * w2 + w3 * w3) / J1
    a1, a2, a3 = free_rate(w1, w2, w3, J, g)
    return free * a1 - k * w1, free * a2 - k * w2, free * a3 - k * w3


@pytest.fixture
def drag_model(monkeypatch):
    """The toy registered for one test, with its row of presentation."""
    model = M.register(M.Model(name="drag", equations="(toy)", summary="isotropic drag", terms=_drag_terms))
    monkeypatch.setitem(presentation.STYLES, "drag", dataclasses.replace(
        presentation.STYLES["free"], color=(200, 120, 0), heading={"outreach": ("Drag", ""), "physics": ("drag", "")}))
    yield model
    M.unregister("drag")


def test_a_third_model_is_one_registry_entry_plus_its_physics(drag_model):
    """Registered, the toy is a valid model for the schema, is integrated by ``auto`` (Taylor's
    method, which builds its rate as written) along its closed form, is refused by the compiled
    methods with the reason, and a scene comparing it with the reduced model reads."""
    body = B.symmetric_top(0.0, 0.0)                   # a sphere: Omega's direction is fixed
    w0 = np.array([0.0, 0.03, 0.04])
    tr = spinviz.simulate(body, "drag", w0, t_end=2e3, samples=50, rtol=1e-12, atol=1e-14)
    assert tr.stats["method"] == "taylor"
    want = np.linalg.norm(w0) / np.sqrt(1.0 + 2.0 * float(w0 @ w0) * tr.t)
    assert np.max(np.abs(np.linalg.norm(tr.omega, axis=1) / want - 1.0)) < 1e-10
    with pytest.raises(spinviz.SpecError, match="method: 'split4' runs on compiled kernels, which do not know the "
                                                "model 'drag'"):
        spinviz.simulate(body, "drag", w0, t_end=10.0, samples=5, method="split4", step=0.1)
    sc = parse_scene({"body": {"delta": 0.3, "chi": 0.7}, "initial": {"omega": [0.0, 0.05, 0.3]},
                      "simulation": {"models": ["reduced", "drag"], "t_end": 10.0, "samples": 5}}, "toy.toml")
    assert sc.models == ("reduced", "drag")
    assert math.isfinite(spinviz.simulate_request(sc.request("drag")).omega[-1, 0])
