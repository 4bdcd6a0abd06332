"""The label placer against a brute-force reference on small random scenes: its lazy costs
(batches, the obstacles the same at every angle tested once, SLACK, MOVE_COST) choose the places
that testing every candidate against every obstacle chooses; a label keeps its place from angle
to angle unless it must move; over many angles a label keeps the place of a searched
neighbouring angle where that place is free (STRIDE); and no label is placed over a hard
obstacle or another label."""
import numpy as np
import pytest

from kinetostat.plans import labels
from kinetostat.plans.labels import LINE_COST, MOVE_COST, SLACK, STRIDE, Placer, _clipped


def _boxes(rng, shape, size=4.0, span=60.0):
    """Random boxes (..., 4) in [0, span], sides up to `size`."""
    xy = rng.uniform(0.0, span, shape + (2,))
    return np.concatenate([xy, xy + rng.uniform(0.2, size, shape + (2,))], axis=-1)


def _lines(rng, shape, span=60.0):
    """Random segments (..., 4): oblique, some horizontal or vertical, some a point."""
    seg = rng.uniform(0.0, span, shape + (4,))
    flat = rng.random(shape) < 0.2
    seg[flat, 3] = seg[flat, 1]                               # horizontal
    upright = rng.random(shape) < 0.2
    seg[upright, 2] = seg[upright, 0]                         # vertical
    dot = rng.random(shape) < 0.05
    seg[dot, 2:] = seg[dot, :2]
    return seg


def _over(box, other):
    """Whether boxes overlap (broadcast, last axis 4; strict: touching is clear)."""
    return (box[..., 0] < other[..., 2]) & (box[..., 2] > other[..., 0]) & (box[..., 1] < other[..., 3]) \
        & (box[..., 3] > other[..., 1])


def _grown(boxes):
    """Boxes grown by the placer's clearance."""
    return boxes + np.array([-Placer.PAD, -Placer.PAD, Placer.PAD, Placer.PAD])


def _scene(seed: int, n: int):
    """A placer with hard obstacles and lines, still and moving (some absent: NaN), and the
    same obstacles as plain arrays for the reference: hard (n, H, 4) grown by PAD, lines (n, S, 4)."""
    rng = np.random.default_rng(seed)
    placer = Placer(n, (0.0, 0.0, 60.0, 60.0))
    still_hard, moving_hard = _boxes(rng, (5,)), _boxes(rng, (n, 4))
    still_lines, moving_lines = _lines(rng, (12,)), _lines(rng, (n, 8))
    moving_hard[rng.random((n, 4)) < 0.2] = np.nan
    moving_lines[rng.random((n, 8)) < 0.2] = np.nan
    placer.block(still_hard[None])                           # (1, S, 4): the same at every angle
    placer.block(moving_hard)
    placer.line(still_lines[None])
    placer.line(moving_lines)
    hard = _grown(np.concatenate([np.broadcast_to(still_hard, (n, 5, 4)), moving_hard], axis=1))
    lines = np.concatenate([np.broadcast_to(still_lines, (n, 12, 4)), moving_lines], axis=1)
    return rng, placer, hard, lines


def _reference_costs(centres, half, base, hard, lines):
    """Every candidate's cost at every angle: inf where not free (its base inf, or over a hard
    obstacle), else its base plus LINE_COST per mm of the lines inside its box."""
    n, K = base.shape
    cost = np.full((n, K), np.inf)
    for i in range(n):
        for k in range(K):
            if not np.isfinite(base[i, k]):
                continue
            c = centres[:, i, k].astype(float)
            box = np.r_[c - half[:, i], c + half[:, i]]
            if not _over(box, hard[i]).any():
                cost[i, k] = base[i, k] + LINE_COST * _clipped(lines[i], box).sum()
    return cost


def _reference_choice(centres, half, base, hard, lines, slack):
    """`_reference_costs`, then the rule: at each angle where some candidate is free, the
    candidates within `slack` of the least; over those angles in order, the run of least total
    cost plus MOVE_COST for each change of candidate (a plain loop over every pair of
    candidates: staying preferred on a tie, then the first by mean finite base)."""
    n, K = base.shape
    cost = _reference_costs(centres, half, base, hard, lines)
    fin = np.isfinite(base)
    typical = np.array([base[fin[:, k], k].mean() if fin[:, k].any() else np.inf for k in range(K)])
    rank = np.argsort(typical, kind="stable")                 # a candidate's place in the order
    best = cost.min(axis=1)
    ok = np.isfinite(cost) & (cost <= best[:, None] + (slack if n > 1 else 0.0))
    chosen = np.where(fin.any(axis=1), rank[np.argmax(np.isfinite(base[:, rank]), axis=1)], -1)
    rows = np.flatnonzero(np.isfinite(best))
    if not len(rows):
        return chosen
    c = [[cost[i, k] if ok[i, k] else np.inf for k in rank] for i in rows]
    total, back = list(c[0]), []
    for row in c[1:]:
        step, new = [], []
        for k in range(K):
            j = min(range(K), key=lambda j: (total[j] + (0.0 if j == k else MOVE_COST), j != k, j))
            step.append(j)
            new.append(total[j] + (0.0 if j == k else MOVE_COST) + row[k])
        back.append(step)
        total = new
    path = [min(range(K), key=lambda k: (total[k], k))]
    for step in reversed(back):
        path.append(step[path[-1]])
    chosen[rows] = rank[path[::-1]]
    return chosen


@pytest.mark.parametrize("still", [False, True], ids=["moving", "still"])
@pytest.mark.parametrize("seed", range(4))
def test_lazy_costs_choose_what_testing_every_candidate_chooses(seed, still):
    """Random anchors among random obstacles, candidates on rings about them (n = 7 angles,
    160 candidates: more than the first batch; a few not free; still: the same candidates at
    every angle): the placer's choice is the brute-force reference's."""
    n, K = 7, 160
    rng, placer, hard, lines = _scene(seed, n)
    anchor = rng.uniform(10.0, 50.0, (1 if still else n, 2))
    reach = np.repeat(np.linspace(0.5, 8.0, K // 16), 16) + rng.uniform(0.0, 0.5, (len(anchor), K))
    turn = np.radians(np.tile(np.arange(0.0, 360.0, 22.5), K // 16))
    centres = (anchor.T[:, :, None] + reach * np.array([np.cos(turn), np.sin(turn)])[:, None]).astype(np.float32)
    base = 1.2 * reach
    near = np.broadcast_to(anchor, (n, 2)) + rng.uniform(-1.0, 1.0, (n, 2))
    blocker = np.concatenate([near, near], axis=1) + rng.uniform(1.0, 7.0, (n, 1)) * np.array([-1, -1, 1, 1])
    placer.block(blocker)                                     # the first rings taken at some angles: later batches
    hard = np.concatenate([hard, _grown(blocker[:, None])], axis=1)
    base[rng.random(base.shape) < 0.1] = np.inf
    centres, base = np.broadcast_to(centres, (2, n, K)), np.broadcast_to(base, (n, K))
    half = np.broadcast_to(rng.uniform(0.8, 3.0, (2, 1)), (2, n)).astype(np.float32)
    got = placer._choose(_geometry(centres, base), K, half, still)
    want = _reference_choice(centres, half, base, hard, lines, SLACK)
    assert np.array_equal(got, want), (got, want)


def test_a_label_keeps_its_place_unless_it_must_move():
    """Two places, each the cheaper by 3 (more than the old slack, 1.5) in turn, three angles at a
    time: the label stays in the place cheaper over all 12 angles (before: it moved every three
    angles); where one place is not free at angles 4-5 and the other at 10-11, it moves once, at 6."""
    n = 12
    placer = Placer(n, (0.0, 0.0, 60.0, 60.0))
    centres = np.broadcast_to(np.array([[10.0, 40.0], [10.0, 40.0]])[:, None], (2, n, 2)).astype(np.float32)
    a = np.array([0.0, 0.0, 0.0, 3.0, 3.0, 3.0] * 2)
    base = np.column_stack([a, 3.5 - a])                    # over the 12: the first 18, the second 24
    half = np.ones((2, n), dtype=np.float32)
    got = placer._choose(_geometry(centres, base), 2, half, False)
    assert got.tolist() == [0] * n
    base[4:6, 0] = base[10:, 1] = np.inf
    got = placer._choose(_geometry(centres, base), 2, half, False)
    assert got.tolist() == [1] * 6 + [0] * 6                 # once, as soon as it is free to
    assert MOVE_COST > SLACK


def _geometry(centres, base):
    """The placer's candidates as given arrays: centres (2, N, K), least costs (N, K)."""
    return lambda rows, cols: (centres[:, rows[:, None], cols], base[rows[:, None], cols])


def _scene_of_candidates(seed: int, n: int, K: int):
    """A scene (`_scene`) with a moving anchor among blockers and K candidates on rings about it."""
    rng, placer, hard, lines = _scene(seed, n)
    anchor = rng.uniform(10.0, 50.0, 2) + np.cumsum(rng.uniform(-0.6, 0.6, (n, 2)), axis=0)    # a point moving on
    reach = np.repeat(np.linspace(0.5, 8.0, K // 16), 16)
    turn = np.radians(np.tile(np.arange(0.0, 360.0, 22.5), K // 16))
    centres = (anchor.T[:, :, None] + reach * np.array([np.cos(turn), np.sin(turn)])[:, None]).astype(np.float32)
    blocker = np.concatenate([anchor, anchor], axis=1) + rng.uniform(0.5, 4.0, (n, 1)) * np.array([-1, -1, 1, 1]) \
        + rng.uniform(-3.0, 3.0, (n, 1)) * np.array([1, 0, 1, 0])
    placer.block(blocker)
    hard = np.concatenate([hard, _grown(blocker[:, None])], axis=1)
    base = np.broadcast_to(1.2 * reach, (n, K)).copy()
    half = np.broadcast_to(rng.uniform(0.8, 3.0, (2, 1)), (2, n)).astype(np.float32)
    return placer, centres, half, base, hard, lines


@pytest.mark.parametrize("seed", range(4))
def test_over_many_angles_a_label_keeps_a_searched_neighbours_place_where_it_is_free(seed):
    """n = 40 angles (>= 2 STRIDE): at every STRIDE-th angle and the last the brute-force
    reference's choice over those angles alone; at an angle between, the place chosen at the
    searched angle before it where free there, else the one after it where free, else the
    reference's choice over the angles left; and at every angle a free place."""
    n, K = 40, 96
    placer, centres, half, base, hard, lines = _scene_of_candidates(seed, n, K)
    got = placer._choose(_geometry(centres, base), K, half, False)
    sample = np.unique(np.r_[np.arange(0, n, STRIDE), n - 1])
    pick = lambda rows: _reference_choice(centres[:, rows], half[:, rows], base[rows], hard[rows], lines[rows], SLACK)
    want = np.full(n, -1)
    want[sample] = pick(sample)
    free = np.isfinite(_reference_costs(centres, half, base, hard, lines))
    left = []
    for i in np.setdiff1d(np.arange(n), sample):
        j = np.searchsorted(sample, i)
        keep = [k for k in (want[sample[j - 1]], want[sample[j]]) if k >= 0 and free[i, k]]
        if keep:
            want[i] = keep[0]
        else:
            left.append(i)
    if left:
        want[left] = pick(np.array(left))
    assert np.array_equal(got, want), np.flatnonzero(got != want)
    assert free[np.arange(n), got].all()
    assert len(left) and (got[1:] != got[:-1]).any()        # the scene moves a label, and searches again


@pytest.mark.parametrize("n", [10, 40])
def test_angles_without_an_anchor_are_not_searched_and_change_no_choice(n):
    """A label without an anchor at some angles (no candidate free there, as `place` gives it;
    n = 10 angles, and 40: searched at every STRIDE-th): those angles are never searched or tested
    (`geometry` never asked for them), -1 there, and every other angle's choice is the one made
    with them searched."""
    K = 96
    placer, centres, half, base, _, _ = _scene_of_candidates(1, n, K)
    anchored = np.ones(n, dtype=bool)
    anchored[[1, 2, 3, n - 3]] = False
    anchored[17:30] = n < 30
    base[~anchored] = np.inf
    want = placer._choose(_geometry(centres, base), K, half, False)
    asked = []

    def geometry(rows, cols):
        asked.append(rows)
        return _geometry(centres, base)(rows, cols)

    got = placer._choose(geometry, K, half, False, anchored=anchored)
    assert np.array_equal(got, want), np.flatnonzero(got != want)
    assert (got[~anchored] == -1).all() and (got[anchored] >= 0).any()
    assert not np.isin(np.flatnonzero(~anchored), np.concatenate(asked)).any()


@pytest.mark.parametrize("seed", range(4))
def test_no_label_is_placed_over_a_hard_obstacle(seed):
    """Eight labels, still and moving, some beside a segment, among random obstacles (n = 6
    angles, and n = 30 where the places are searched at every STRIDE-th angle): at every angle
    each box lies in the bounds, off every hard obstacle (grown by the clearance) and off every
    label placed before it."""
    for n in (6, 30):
        _labels_clear(seed, n)


def _labels_clear(seed: int, n: int) -> None:
    rng, placer, hard, _ = _scene(seed, n)
    placed = []
    for j in range(8):
        anchor = np.broadcast_to(rng.uniform(10.0, 50.0, 2), (n, 2)) if j % 3 == 0 else rng.uniform(10.0, 50.0, (n, 2))
        along = anchor + rng.uniform(-15.0, 15.0, (n, 2)) if j % 2 else None
        box = placer.place(("B" + "1" * j, "C"), rng.integers(0, 2, n), 3.5, anchor, along).box
        assert np.isfinite(box).all()
        assert (box[:, :2] >= 0.0).all() and (box[:, 2:] <= 60.0).all()
        for other in [hard, *(_grown(b[:, None]) for b in placed)]:
            over = _over(box[:, None], other)
            assert not over.any(), (j, np.argwhere(over))
        placed.append(box)


def test_clear_tells_a_box_that_meets_a_hard_obstacle_at_its_angle():
    """`Placer.clear` (the page's notes of every angle shown only where clear): a box over an
    arrowhead at its angle is not clear, the same box at an angle where the arrowhead is elsewhere
    is; a box 0.2 mm off it is clear (meeting counts, not the labels' PAD); NaN is not clear."""
    pl = Placer(3, (0.0, 0.0, 100.0, 100.0))
    pl.block(np.array([[10.0, 10.0, 12.0, 12.0], [50.0, 50.0, 52.0, 52.0], [10.0, 10.0, 12.0, 12.0]]))
    over = np.array([11.0, 11.0, 20.0, 14.0])
    assert pl.clear(np.array([over, over, [np.nan] * 4])).tolist() == [False, True, False]
    beside = np.array([12.2, 10.0, 20.0, 12.0])
    assert pl.clear(np.array([beside] * 3)).tolist() == [True, True, True]


def test_a_label_keeps_off_heavy_lines_that_it_would_cover_were_they_thin():
    """A point where twelve lines meet 30 deg apart (a force polygon's vertex, the links at a
    pin): over thin lines its label stays next to it, over some of them (a line costs LINE_COST
    a mm); over heavy ones (links, vectors) it goes out where none of them meets its box, with a
    leader back to the point."""
    t = np.radians(np.arange(0.0, 360.0, 30.0))
    star = np.column_stack([np.full(12, 30.0), np.full(12, 30.0), 30.0 + 25.0 * np.cos(t), 30.0 + 25.0 * np.sin(t)])
    for heavy in (False, True):
        placer = Placer(1, (0.0, 0.0, 60.0, 60.0))
        placer.line(star[None], heavy)
        placed = placer.place(("B",), np.zeros(1, dtype=int), 3.5, np.array([[30.0, 30.0]]))
        covered = sum(_clipped(s, placed.box[0]) for s in star)
        assert (covered == 0 and np.allclose(placed.leader[0, :2], 30.0)) if heavy else \
            (covered > 1.0 and np.isnan(placed.leader).all()), (heavy, placed)


def _eight_round_one_point(n: int) -> tuple[np.ndarray, np.ndarray, list]:
    """Eight labels of one point (a pin and the loads on it: B, F_i3, R_43, ...) on a clear sheet,
    at n angles, the point moving: the point (n, 2) and each label's box centre (8, n, 2), and
    the labels placed."""
    anchor = np.column_stack([50.0 + 5.0 * np.sin(np.arange(n) / 7.0), np.full(n, 50.0)])
    placer = Placer(n, (0.0, 0.0, 100.0, 100.0))
    placer.block(np.concatenate([anchor - 0.6, anchor + 0.6], axis=1))        # the point's dot
    placed = [placer.place((name,), np.zeros(n, dtype=int), 3.5, anchor)
              for name in ("B", "F_i3", "R_43", "G_3", "x_43", "h_G2", "h_Fi2", "F_p")]
    return anchor, np.stack([(p.box[:, :2] + p.box[:, 2:]) / 2 for p in placed]), placed


@pytest.mark.parametrize("n", [1, 40], ids=["one angle", "a page's angles"])
def test_labels_that_would_crowd_round_a_point_go_out_on_leaders(n, monkeypatch):
    """Eight labels of one point on a clear sheet (one angle; 40, searched at every STRIDE-th):
    without the crowding cost all eight lie within 15 mm of it (the teacher's crowd at B); with
    it at most five do, at every angle, and each of the others is out on a leader that starts at
    the point and ends on its box."""
    anchor, centres, placed = _eight_round_one_point(n)
    inside = np.hypot(*(centres - anchor).transpose(2, 0, 1)) <= 15.0                    # (8, n)
    assert inside.sum(axis=0).max() <= 5
    for p, near in zip(placed, inside):
        lead = p.leader[~near]
        assert np.isfinite(lead).all() and np.allclose(lead[:, :2], anchor[~near])
        assert ((lead[:, 2:] >= p.box[~near, :2] - 1e-9) & (lead[:, 2:] <= p.box[~near, 2:] + 1e-9)).all()
    monkeypatch.setattr(labels, "CROWD_COST", 0.0)
    anchor, centres, _ = _eight_round_one_point(n)
    assert (np.hypot(*(centres - anchor).transpose(2, 0, 1)) <= 15.0).all()
