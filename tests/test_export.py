"""Export for engine users (validation/export.py, `kinetostat export`): the MJCF loads in MuJoCo
and its keyframe is the assembled mechanism; the URDF parses, loads in Pinocchio with the
model's joints and moving mass, and places every centre of mass where kinetostat does."""
from __future__ import annotations

import math
import os
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import kinetostat
from conftest import EVERY_GROUP, MODELS, ROOT, sampled
from kinetostat_validation.export import to_mjcf, to_urdf
from kinetostat_validation.scene import build_scene

ICE = ROOT / "models" / "ice_crank_slider.toml"
def _com_positions(mech) -> dict[int, np.ndarray]:
    """kinetostat's centre of mass of every link with mass at phi = 0, world, m."""
    res = kinetostat.analyze(mech, phi_deg=[0.0])
    return {k.id: res.position(k.com)[0] for k in mech.links[1:] if k.com and k.mass > 0}


@pytest.mark.parametrize("path", sampled(MODELS, EVERY_GROUP))
def test_mjcf_loads_in_mujoco_and_its_keyframe_is_assembled(path):
    mujoco = pytest.importorskip("mujoco")
    mech = kinetostat.load(path)
    scene = build_scene(mech, phi_deg=[0.0])
    n_slots = sum(p.kind == "P" for p in scene.cuts)
    m = mujoco.MjModel.from_xml_string(to_mjcf(mech))
    assert m.nbody == mech.n_links + n_slots             # world + moving links + slot helpers
    assert m.njnt == mech.n_links - 1 + n_slots
    assert m.neq == len(scene.cuts) == len(mech.pairs) - (mech.n_links - 1)
    heaviest = max(k.mass for k in mech.links)
    for link in mech.links[1:]:
        mass = m.body_mass[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"link{link.id}")]
        if link.mass > 0:
            assert mass == link.mass
        else:
            assert 0 < mass <= 1e-6 * heaviest           # MuJoCo's placeholder for a massless link
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "phi0"))
    mujoco.mj_forward(m, d)
    size = mech.size
    assert np.abs(d.efc_pos[:d.ne]).max() <= 1e-12 * size                   # loops closed
    assert np.abs(d.efc_vel[:d.ne]).max() <= 1e-12 * size * mech.drive.omega  # and moving consistently
    for k, S in _com_positions(mech).items():
        xipos = d.xipos[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"link{k}")]
        np.testing.assert_allclose(xipos[:2], S, rtol=0, atol=1e-12 * size)


def _pin_q(pin, model, values: dict[str, float]) -> np.ndarray:
    """Pinocchio configuration from joint name -> angle (rad) or travel (m)."""
    q = pin.neutral(model)
    for name, x in values.items():
        j = model.joints[model.getJointId(name)]
        q[j.idx_q:j.idx_q + j.nq] = [math.cos(x), math.sin(x)] if j.nq == 2 else [x]
    return q


@pytest.mark.parametrize("path", sampled(MODELS, EVERY_GROUP))
def test_urdf_parses_and_loads_in_pinocchio_with_the_moving_mass(path):
    mech = kinetostat.load(path)
    text = to_urdf(mech)
    root = ET.fromstring(text)
    scene = build_scene(mech, phi_deg=[0.0])
    assert len(root.findall("link")) == mech.n_links
    assert len(root.findall("joint")) == mech.n_links - 1
    assert text.count("<!-- loop closure:") == len(scene.cuts) >= 1
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromXML(text)
    assert model.njoints == mech.n_links                  # the universe + one joint per moving link
    assert sum(I.mass for I in model.inertias) == pytest.approx(sum(k.mass for k in mech.links), rel=1e-15)

    # at the assembled configuration every centre of mass sits where kinetostat puts it ...
    data = model.createData()
    q = _pin_q(pin, model, {f"pair{j.pair.index}": scene.q[0, n] for n, j in enumerate(scene.joints)})
    pin.forwardKinematics(model, data, q)
    link_joint = {int(j.find("child").get("link")[4:]): model.getJointId(j.get("name")) for j in root.findall("joint")}
    for k, S in _com_positions(mech).items():
        jid = link_joint[k]
        np.testing.assert_allclose(data.oMi[jid].act(model.inertias[jid].lever)[:2], S, rtol=0, atol=1e-12 * mech.size)

    # ... and the two points of every revolute loop closure, as the comments give them, coincide
    world = lambda k, xyz: (data.oMi[link_joint[k]].act(np.array(xyz)) if k else np.array(xyz))[:2]
    closures = re.findall(
        r"loop closure: revolute pair .*?link(\d+) \(xyz ([^)]*)\) coincides with .*?link(\d+) \(xyz ([^)]*)\)", text)
    assert len(closures) == sum(p.kind == "R" for p in scene.cuts)
    for a_link, a_xyz, b_link, b_xyz in closures:
        A = world(int(a_link), list(map(float, a_xyz.split())))
        B = world(int(b_link), list(map(float, b_xyz.split())))
        np.testing.assert_allclose(A, B, rtol=0, atol=1e-12 * mech.size)


# ----------------------------------------------------------------------------- command line

def test_cli_writes_both_formats(tmp_path, cli):
    mech = kinetostat.load(ICE)
    r = cli("export", ICE, "--mjcf", "-o", tmp_path / "ice.xml", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "ice.xml").read_text(encoding="utf-8") == to_mjcf(mech)
    r = cli("export", ICE, "--urdf", "-o", tmp_path / "ice.xml", cwd=tmp_path)        # replaces the file
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "ice.xml").read_text(encoding="utf-8") == to_urdf(mech)
    assert sorted(os.listdir(tmp_path)) == ["ice.xml"]                        # no temporary file left
    r = cli("export", ICE, "--urdf", cwd=tmp_path)                                      # stdout
    assert r.returncode == 0 and r.stdout == to_urdf(mech)


@pytest.mark.parametrize("args, message", [
    ((ICE,), "one of the arguments --mjcf --urdf is required"),
    ((ICE, "--mjcf", "--urdf"), "not allowed with argument"),
    ((ICE, "--mjcf", "-o", "missing/dir/ice.xml"), "cannot write -o missing/dir/ice.xml"),
    ((ICE, "--mjcf", "-o", "."), "it is a directory"),
    (("nope.toml", "--urdf"), "model file not found: nope.toml"),
])
def test_cli_bad_input_is_one_line(tmp_path, cli, args, message):
    r = cli("export", *args, cwd=tmp_path)
    assert r.returncode == 2
    assert message in r.stderr and len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr
    assert os.listdir(tmp_path) == []
