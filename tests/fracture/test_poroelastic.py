"""Undrained constants from drained ones (ref. Eqs 5.19-5.21) against ref. Table 5.2,
and the [poroelastic] scene section that runs the DDM with them."""
import pytest

from hmatddm.errors import InputError
from hmatddm.fracture.poroelastic import UndrainedRock, from_undrained_bulk_modulus

G, K, ALPHA, PHI = 6.62e9, 11.03e9, 0.8, 0.15  # ref. Table 5.2
OIL, GAS = 2.2e9, 30.0e6


def _independent(k_f):
    """Eqs 5.19-5.21 written out as printed (K_s from Eq. 5.20), apart from the module."""
    k_s = K / (1.0 - ALPHA)
    k_u = K + ALPHA**2 * k_s * k_f / (PHI * k_s + (ALPHA - PHI) * k_f)
    return k_u, (k_u - K) / (ALPHA * k_u)


@pytest.mark.parametrize("k_f, k_u_printed, nu_printed, b_printed",
                         [(OIL, "19.03", "0.3441", "0.5255"), (GAS, "11.16", "0.2524", "0.01456")], ids=["oil", "gas"])
def test_table_5_2_derived_values(k_f, k_u_printed, nu_printed, b_printed):
    rock = UndrainedRock(G, K, ALPHA, k_f, PHI)
    # K_u to the printed digits (two decimals in GPa)
    assert f"{rock.undrained_bulk_modulus / 1e9:.2f}" == k_u_printed
    k_u, b = _independent(k_f)
    assert rock.undrained_bulk_modulus == pytest.approx(k_u, rel=1e-13)
    assert rock.skempton == pytest.approx(b, rel=1e-12)
    # the table computed nu_u and B from its rounded K_u: every printed digit from it
    nu_u, b_table = from_undrained_bulk_modulus(float(k_u_printed) * 1e9, K, G, ALPHA)
    digits = len(b_printed.split(".")[1])
    assert f"{nu_u:.4f}" == nu_printed and f"{b_table:.{digits}f}" == b_printed
    # nu_u, 3 K_u and G are those of one isotropic solid: 2 G (1 + nu) = 3 K (1 - 2 nu)
    assert 2 * G * (1 + rock.undrained_poisson_ratio) == pytest.approx(
        3 * rock.undrained_bulk_modulus * (1 - 2 * rock.undrained_poisson_ratio), rel=1e-12)


def test_unrounded_values_differ_from_the_table_where_the_rounding_bites():
    oil, gas = UndrainedRock(G, K, ALPHA, OIL, PHI), UndrainedRock(G, K, ALPHA, GAS, PHI)
    assert f"{oil.undrained_poisson_ratio:.4f}" == "0.3442" and f"{oil.skempton:.4f}" == "0.5256"
    assert f"{gas.skempton:.5f}" == "0.01431"  # the table's 0.01456 is from K_u rounded to 11.16 GPa


def test_limits_and_the_drained_poisson_ratio():
    # incompressible grains (alpha = 1): K_u = K + K_f / phi (Gassmann with K_s -> inf)
    rock = UndrainedRock(G, K, 1.0, OIL, PHI)
    assert rock.undrained_bulk_modulus == pytest.approx(K + OIL / PHI, rel=1e-14)
    assert rock.solid_bulk_modulus == float("inf")
    # a very soft fluid leaves the rock drained: K_u -> K, B -> 0, nu_u -> nu
    soft = UndrainedRock(G, K, ALPHA, 1.0, PHI)
    assert soft.skempton < 1e-9 and soft.undrained_poisson_ratio == pytest.approx(soft.drained_poisson_ratio, abs=1e-9)
    via_nu = UndrainedRock.from_poisson_ratio(G, 0.25, ALPHA, OIL, PHI)
    assert via_nu.bulk_modulus == pytest.approx(2 * G * 1.25 / 1.5, rel=1e-14)
    assert via_nu.drained_poisson_ratio == pytest.approx(0.25, rel=1e-14)


@pytest.mark.parametrize("kwargs, field", [
    (dict(biot=0.1), "poroelastic.biot"), (dict(biot=1.2), "poroelastic.biot"),
    (dict(porosity=0.0), "poroelastic.porosity"), (dict(fluid_bulk_modulus=-1.0), "poroelastic.fluid_bulk_modulus"),
    (dict(bulk_modulus=float("nan")), "poroelastic.bulk_modulus")])
def test_bad_input_names_the_field(kwargs, field):
    values = {**dict(shear_modulus=G, bulk_modulus=K, biot=ALPHA, fluid_bulk_modulus=OIL, porosity=PHI), **kwargs}
    with pytest.raises(InputError, match=field.replace(".", r"\.")):
        UndrainedRock(**values)


SCENE = """
dimension = 2
[material]
shear_modulus = 6.62e9
poisson_ratio = 0.2499370435658524
[fluid]
viscosity = 1e-3
[stress]
s_hmin = 35.85e6
s_hmax = 39.44e6
[[cluster]]
position = [0.0, 0.0]
rate = 1e-4
[[initial_fracture]]
p0 = [-2.0, 0.0]
p1 = [2.0, 0.0]
element_size = 1.0
[numerics]
end_time = 1.0
time_step = 1.0
[leak_off]
pore_pressure = 30.2e6
[[natural_fracture]]
p0 = [1.0, 2.0]
p1 = [3.0, 4.0]
[poroelastic]
biot = 0.8
fluid_bulk_modulus = 2.2e9
porosity = 0.15
"""


def test_scene_section_runs_the_ddm_undrained(tmp_path, capsys):
    import tomllib

    from hmatddm.app import cli
    from hmatddm.scene import validate
    from hmatddm.scene.build import material, natural_properties

    scene = validate(tomllib.loads(SCENE))
    oil = UndrainedRock(G, K, ALPHA, OIL, PHI)
    assert material(scene).poisson_ratio == pytest.approx(oil.undrained_poisson_ratio, rel=1e-9)
    assert material(scene).shear_modulus == G
    assert natural_properties(scene).skempton == pytest.approx(oil.skempton, rel=1e-9)
    assert validate(scene) == scene  # the echo validates to itself
    drained = validate(tomllib.loads(SCENE.split("[poroelastic]")[0]))
    assert material(drained).poisson_ratio == pytest.approx(0.24994, abs=1e-5)
    assert natural_properties(drained).skempton == 0.0
    path = tmp_path / "poro.toml"
    path.write_text(SCENE)
    assert cli.main(["run", str(path), "--check"]) == cli.EXIT_OK
    err = capsys.readouterr().err
    assert "K_u = 19.03 GPa" in err and "nu_u = 0.3442" in err and "Skempton B = 0.5256" in err
    with pytest.raises(InputError, match="poroelastic.biot must be >= poroelastic.porosity"):
        validate(tomllib.loads(SCENE.replace("biot = 0.8", "biot = 0.1")))
    with pytest.raises(InputError, match="poroelastic.porosity is required"):
        validate(tomllib.loads(SCENE.replace("porosity = 0.15", "")))
