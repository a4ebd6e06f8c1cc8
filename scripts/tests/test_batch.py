"""dyadfmu.solve over NumPy arrays: every row bit for bit the scalar solve's, one status
per row, broadcasting, and errors that name the bad field."""

from __future__ import annotations

import dataclasses

import dyadfmu
import numpy as np
import pytest
from dyadfmu.batch import FIELDS, default_core
from dyadfmu.core import LINK_KEYS, TYPES, Core
from dyadfmu.study.configurations import random_set

ROWS = 300


@pytest.fixture(scope="module")
def core() -> Core:
    return default_core()


def keywords(rows: np.ndarray) -> dict[str, np.ndarray]:
    """The study's rows (35 columns in dyad_input's order) as solve's keywords."""
    out, c = {}, 0
    for name, width in FIELDS:
        out[name] = rows[:, c : c + width] if width == 2 else rows[:, c]
        c += width
    return out


def scalar_inputs(fields: dict[str, np.ndarray], r: int) -> tuple:
    """Row r as the arguments of Core.solve."""
    links = [{key: fields[f"{g}_{key}"][r] for key in LINK_KEYS} for g in "mn"]
    return (*links, fields["guide_k"][r], fields["guide_p"][r], fields["gravity"][r])


def same(a: float, b: float) -> bool:
    return a == b or (np.isnan(a) and np.isnan(b))


@pytest.mark.parametrize("dyad", TYPES)
def test_rows_match_the_scalar_solve_bit_for_bit(core, dyad):
    rows = random_set(dyad, ROWS, seed=7)
    rows[::29, 9] = np.nan  # link_m.mass: invalid rows among valid ones
    rows[5::31, 16] = -1.0  # link_n.length
    fields = keywords(rows)
    got = dyadfmu.solve(dyad, **fields)
    assert got.r_mk.shape == (ROWS, 2) and got.n_mk.shape == (ROWS,)
    statuses = {"ok": 0, "singular": 1, "invalid input": 2, "out of range": 3}
    for r in range(ROWS):
        want = core.solve(dyad, *scalar_inputs(fields, r), singular_threshold=rows[r, 34])
        assert got.status[r] == statuses[want["status"]], r
        assert core.field_name(got.field[r]) == want["field"], r
        for name in ("r_mk", "r_np", "r_mn"):
            assert same(got.__dict__[name][r, 0], want[name][0]), (r, name)
            assert same(got.__dict__[name][r, 1], want[name][1]), (r, name)
        for name in ("n_mk", "n_np", "n_mn", "m_mk", "m_np", "m_mn", "conditioning"):
            assert same(got.__dict__[name][r], want[name]), (r, name)
        assert same(got.amplification[r], want["amplification"]), r
    assert not got.ok[::29].any()
    assert got.reason(0) == "invalid input: link_m.mass"
    assert np.isnan(got.r_mn[0]).all()


def test_broadcast_and_strided_inputs_give_the_same_rows():
    rows = random_set("RRT", 60, seed=3)
    fields = keywords(rows)
    base = dyadfmu.solve("RRT", **fields)
    # one value given once for all rows, a batch of shape (6, 10), a reversed view
    once = dict(fields, gravity=np.array([0.0, -9.81]), m_mass=2.5)
    full = dict(
        fields,
        gravity=np.tile([0.0, -9.81], (60, 1)),
        m_mass=np.full(60, 2.5),
    )
    a, b = dyadfmu.solve("RRT", **once), dyadfmu.solve("RRT", **full)
    np.testing.assert_array_equal(a.r_np, b.r_np)
    assert not np.array_equal(a.r_np, base.r_np)  # the change of mass and weight shows
    shaped = dyadfmu.solve("rrt", **{k: v.reshape((6, 10, *v.shape[1:])) for k, v in full.items()})
    assert shaped.r_mk.shape == (6, 10, 2) and shaped.status.shape == (6, 10)
    np.testing.assert_array_equal(shaped.r_mk.reshape(60, 2), b.r_mk)
    reversed_rows = dyadfmu.solve("RRT", **{k: v[::-1] for k, v in full.items()})
    np.testing.assert_array_equal(reversed_rows.m_mk[::-1], b.m_mk)


def test_fields_left_out_keep_their_defaults(core):
    got = dyadfmu.solve("RRT", m_mass=[1.0, 2.0], m_com=[0.5, 0.0], m_omega=3.0)
    assert got.ok.all()
    want = core.solve(
        "RRT",
        {
            **dict.fromkeys(LINK_KEYS, 0.0),
            "dir": (1, 0),
            "length": 1.0,
            "com": (0.5, 0.0),
            "mass": 2.0,
            "omega": 3.0,
            "accel_d": (0, 0),
            "force": (0, 0),
        },
        {
            **dict.fromkeys(LINK_KEYS, 0.0),
            "dir": (1, 0),
            "length": 1.0,
            "com": (0, 0),
            "accel_d": (0, 0),
            "force": (0, 0),
        },
        (1.0, 0.0),
        (1.0, 0.0),
    )
    assert got.r_mk[1, 0] == want["r_mk"][0] and got.r_mk[1, 1] == want["r_mk"][1]


def test_bad_calls_name_what_is_wrong():
    with pytest.raises(ValueError, match="unknown dyad type 'RRX'"):
        dyadfmu.solve("RRX", m_mass=1.0)
    with pytest.raises(TypeError, match="unknown field 'm_mas'"):
        dyadfmu.solve("RRR", m_mas=1.0)
    with pytest.raises(ValueError, match="m_mass must be real numbers"):
        dyadfmu.solve("RRR", m_mass="heavy")
    with pytest.raises(ValueError, match="n_moment must be real numbers"):
        dyadfmu.solve("RRR", n_moment=[1 + 2j])
    with pytest.raises(ValueError, match="m_force is a vector"):
        dyadfmu.solve("RRR", m_force=[1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="do not broadcast.*m_mass \\(3,\\).*n_mass \\(4,\\)"):
        dyadfmu.solve("RRR", m_mass=np.ones(3), n_mass=np.ones(4))


def test_an_empty_batch_is_empty():
    got = dyadfmu.solve("RTR", m_mass=np.zeros(0))
    assert got.r_mk.shape == (0, 2) and got.status.shape == (0,)


def test_out_takes_the_results_in_place():
    rows = random_set("RTR", 40, seed=11)
    first = dyadfmu.solve("RTR", **keywords(rows))
    kept = {name: getattr(first, name) for name in first.__dataclass_fields__}
    other = random_set("RTR", 40, seed=12)
    again = dyadfmu.solve("RTR", out=first, **keywords(other))
    fresh = dyadfmu.solve("RTR", **keywords(other))
    assert again is first
    for name, array in kept.items():
        assert getattr(again, name) is array  # the same arrays, overwritten
        np.testing.assert_array_equal(array, getattr(fresh, name))


def test_out_of_another_shape_is_refused_by_name():
    rows = random_set("RRR", 10, seed=5)
    small = dyadfmu.solve("RRR", **keywords(rows[:4]))
    with pytest.raises(ValueError, match=r"out\.r_mk must be .* shape \(10, 2\)"):
        dyadfmu.solve("RRR", out=small, **keywords(rows))
    frozen = dyadfmu.solve("RRR", **keywords(rows))
    frozen.status.flags.writeable = False
    with pytest.raises(ValueError, match=r"out\.status must be a writable"):
        dyadfmu.solve("RRR", out=frozen, **keywords(rows))


def test_out_sharing_memory_with_an_input_is_refused():
    rows = random_set("RRR", 30, seed=8)
    fields = keywords(rows)
    first = dyadfmu.solve("RRR", **fields)
    before = first.n_mk.copy()
    # an output fed back as an input of the batch that overwrites it
    with pytest.raises(ValueError, match=r"out\.n_mk shares memory with an input"):
        dyadfmu.solve("RRR", out=first, **dict(fields, m_moment=first.n_mk))
    np.testing.assert_array_equal(first.n_mk, before)  # nothing was written
    # a copy of it is fine
    dyadfmu.solve("RRR", out=first, **dict(fields, m_moment=first.n_mk.copy()))


def test_partial_overlaps_are_refused_and_neighbours_are_not():
    rows = random_set("RRR", 30, seed=9)
    fields = keywords(rows)
    first = dyadfmu.solve("RRR", **fields)
    # an input that starts inside an output (its y components)
    with pytest.raises(ValueError, match=r"out\.r_mk shares memory with an input"):
        dyadfmu.solve("RRR", out=first, **dict(fields, m_moment=first.r_mk[:, 1]))
    # an output that starts inside an input
    shared = np.ascontiguousarray(np.concatenate([fields["m_inertia"], fields["m_inertia"]]))
    inside = dataclasses.replace(first, n_np=shared[10:40])
    with pytest.raises(ValueError, match=r"out\.n_np shares memory with an input"):
        dyadfmu.solve("RRR", out=inside, **dict(fields, m_inertia=shared[:30]))
    # an output right after an input in the same buffer: no byte shared
    after = dataclasses.replace(first, n_np=shared[30:60])
    done = dyadfmu.solve("RRR", out=after, **dict(fields, m_inertia=shared[:30]))
    np.testing.assert_array_equal(done.n_np, first.n_np)


def test_contiguous_fields_read_in_place_match_strided_ones():
    rows = random_set("RTT", 200, seed=10)
    strided = keywords(rows)
    contiguous = {name: np.ascontiguousarray(a) for name, a in strided.items()}
    a, b = dyadfmu.solve("RTT", **strided), dyadfmu.solve("RTT", **contiguous)
    for name in (f.name for f in dataclasses.fields(a)):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_values_beyond_a_double_or_complex_are_refused_by_name():
    with pytest.raises(ValueError, match=r"m_mass must be real numbers within a double's range"):
        dyadfmu.solve("RRR", m_mass=10**400)
    with pytest.raises(ValueError, match=r"n_inertia must be real numbers within a double's"):
        dyadfmu.solve("RRR", n_inertia=[1.0, -(10**400)])
    for value in (np.array([1 + 2j]), np.complex128(2j), [np.array([1j, 0])]):
        with pytest.raises(ValueError, match=r"m_moment must be real numbers: not complex"):
            dyadfmu.solve("RRR", m_moment=value)
    # real numbers of any kind are taken as before
    a = dyadfmu.solve("RRR", m_mass=np.array([2], np.int32), n_mass=np.float32(1.5))
    b = dyadfmu.solve("RRR", m_mass=np.array([2.0]), n_mass=1.5)
    np.testing.assert_array_equal(a.r_mn, b.r_mn)


def test_out_of_another_kind_is_refused_saying_what_was_given():
    first = dyadfmu.solve("RRR", m_mass=np.ones(3))
    with pytest.raises(TypeError, match=r"out must be the Reactions .* not dict \{'r_mk': 1\}"):
        dyadfmu.solve("RRR", out={"r_mk": 1}, m_mass=np.ones(3))
    wrong = dataclasses.replace(first, r_mk=1)
    with pytest.raises(ValueError, match=r"out\.r_mk must be .* shape \(3, 2\), not int 1$"):
        dyadfmu.solve("RRR", out=wrong, m_mass=np.ones(3))


def test_outputs_sharing_memory_are_refused_naming_both():
    rows = random_set("RRR", 30, seed=13)
    fields = keywords(rows)
    first = dyadfmu.solve("RRR", **fields)
    same = np.zeros((30, 2))
    with pytest.raises(ValueError, match=r"out\.r_mk and out\.r_np share memory"):
        dyadfmu.solve("RRR", out=dataclasses.replace(first, r_mk=same, r_np=same), **fields)
    # one output starting inside another (the one input elsewhere)
    shared = np.zeros(50)
    inside = dataclasses.replace(first, n_mk=shared[:30], n_np=shared[20:])
    with pytest.raises(ValueError, match=r"out\.n_mk and out\.n_np share memory"):
        dyadfmu.solve("RRR", out=inside, m_mass=np.ones(30))
    # neighbours in one buffer share no byte: each gets its own results
    shared = np.zeros(60)
    apart = dataclasses.replace(first, n_mk=shared[:30], n_np=shared[30:])
    done = dyadfmu.solve("RRR", out=apart, **fields)
    fresh = dyadfmu.solve("RRR", **fields)
    np.testing.assert_array_equal(done.n_mk, fresh.n_mk)
    np.testing.assert_array_equal(done.n_np, fresh.n_np)


def _link(**changes) -> dict:
    link = dict(
        dir=(1.0, 0.0), length=1.0, omega=0.5, epsilon=0.1, accel_d=(0.0, 0.0), com=(0.5, 0.0)
    )
    link.update(mass=2.0, inertia=0.2, force=(1.0, 0.0), moment=0.3)
    link.update(changes)
    return link


def test_the_scalar_solve_refuses_bad_links_by_name(core):
    n = _link(dir=(0.0, 1.0))
    with pytest.raises(ValueError, match=r"link m: unknown keys \['masss'\]"):
        core.solve("RRR", _link(masss=1.0), n)
    with pytest.raises(ValueError, match=r"m\['dir'\] must be a vector \(x, y\) .* \(1, 0, 5\)"):
        core.solve("RRR", _link(dir=(1, 0, 5)), n)
    without_mass = _link()
    del without_mass["mass"]
    with pytest.raises(ValueError, match=r"link n: missing keys \['mass'\]"):
        core.solve("RRR", _link(), without_mass)
    with pytest.raises(ValueError, match=r"n\['moment'\] must be a real number, not 1j"):
        core.solve("RRR", _link(), _link(dir=(0.0, 1.0), moment=1j))
    with pytest.raises(ValueError, match=r"gravity must be a vector"):
        core.solve("RRR", _link(), n, gravity=9.81)


def test_the_scalar_solve_takes_the_types_dyadfmu_solve_takes(core):
    m, n = _link(), _link(dir=(0.0, 1.0))
    lower, upper = core.solve("rrr", m, n), core.solve("RRR", m, n)
    assert upper["status"] == "ok" and lower == upper
    batch = dyadfmu.solve(
        "rrr", **{f"m_{k}": v for k, v in m.items()}, **{f"n_{k}": v for k, v in n.items()}
    )
    assert tuple(batch.r_mk) == upper["r_mk"]
    with pytest.raises(ValueError, match="unknown dyad type 'rrx'"):
        core.solve("rrx", m, n)
