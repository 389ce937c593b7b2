"""Every evaluation function stays finite and float32 at extreme float32 inputs."""
import numpy as np
import pytest

from rt_lookdev.core import cloth, diffuse, falloff, fresnel, microfacet, multiscatter, rough_diffuse, sheen

F = np.float32
COS = np.array([-1.0, -1e-7, 0.0, 1e-7, 0.5, 1.0 - 1e-7, 1.0], dtype=F)
UNIT = np.array([0.0, 1e-7, 1e-4, 0.5, 1.0 - 1e-7, 1.0], dtype=F)


def grid(*axes):
    return np.meshgrid(*axes, indexing="ij")


CASES = {
    "ggx_brdf": lambda: microfacet.ggx_brdf(*grid(COS, COS, COS, COS, UNIT)),
    "fresnel_schlick": lambda: fresnel.fresnel_schlick(*grid(UNIT, COS)),
    "kulla_conty_brdf": lambda: multiscatter.kulla_conty_brdf(*grid(UNIT, UNIT, UNIT, UNIT)),
    "turquin_compensation": lambda: multiscatter.turquin_compensation(*grid(UNIT, UNIT)),
    "fdez_aguera_env_brdf": lambda: multiscatter.fdez_aguera_env_brdf(*grid(UNIT, UNIT, UNIT)),
    "cod_multiscatter_diffuse": lambda: diffuse.cod_multiscatter_diffuse(F(0.8), *grid(COS, COS, COS, COS, UNIT)),
    "cod_gloss_from_alpha": lambda: diffuse.cod_gloss_from_alpha(UNIT),
    "wrapped_diffuse_cosine": lambda: diffuse.wrapped_diffuse_cosine(*grid(COS, UNIT)),
    "ashikhmin_cloth_brdf": lambda: cloth.ashikhmin_cloth_brdf(*grid(COS, COS, COS, UNIT)),
    "disney_sheen": lambda: cloth.disney_sheen(COS),
    "window_falloff": lambda: falloff.window_falloff(*grid(UNIT * F(10), UNIT * F(10))),
    "inverse_square_falloff": lambda: falloff.inverse_square_falloff(UNIT),
    "cone_falloff": lambda: falloff.cone_falloff(*grid(COS, UNIT * F(3.1), UNIT * F(3.1))),
    "projector_distance": lambda: falloff.projector_distance(*grid(UNIT, UNIT * F(3.1))),
    # the sheen LTC at every direction of the grid, a and b from 0 (Cycles' dropped cells) to beyond the table's
    "zeltner_density": lambda: sheen.zeltner_density(*grid(COS, COS, COS, UNIT, COS * F(2))),
    "zeltner_packed_inverse": lambda: np.stack(np.broadcast_arrays(*sheen.zeltner_packed_inverse(*grid(UNIT, COS)))),
    "zeltner_roughness": lambda: sheen.zeltner_roughness(UNIT),
}
CASES.update({
    "fon_single_scatter_cos": lambda: rough_diffuse.fon_single_scatter_cos(*grid(COS, COS, COS, UNIT)),
    "rough_diffuse_multiscatter_cos": lambda: rough_diffuse.multiscatter_cos(*grid(COS, COS, UNIT)),
    "fon_albedo": lambda: rough_diffuse.fon_albedo(*grid(COS, UNIT)),
    "fon_one_minus_albedo": lambda: rough_diffuse.fon_one_minus_albedo(*grid(COS, UNIT)),
    "fon_average_albedo": lambda: rough_diffuse.fon_average_albedo(UNIT),
    "rough_diffuse_multiscatter_albedo": lambda: rough_diffuse.multiscatter_albedo(*grid(UNIT, UNIT)),
})


@pytest.mark.parametrize("name", sorted(CASES))
def test_finite_and_float32(name):
    with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):  # exp(-big) -> 0 is fine
        value = CASES[name]()
    assert value.dtype == np.float32, value.dtype
    assert np.all(np.isfinite(value))


def _directions():
    """Unit float32 directions: the poles, the equator, tiny tilts, and random ones."""
    rng = np.random.default_rng(4)
    special = [[0, 0, 1], [0, 0, -1], [1, 0, 0], [0, 1e-7, 1], [0, 1e-7, -1], [1e-20, 0, -1]]
    rand = rng.normal(size=(10, 3))
    d = np.concatenate([np.asarray(special, np.float64), rand])
    return (d / np.linalg.norm(d, axis=-1, keepdims=True)).astype(F)


def test_cod_wrapped_diffuse_float32_degenerate():
    """The multiscattering wrapped diffuse at float32 extremes: light at -N (its wrapped direction is 0), light and
    view at the poles, w = 0 and 1, alpha at the floor."""
    d = _directions()
    n = np.broadcast_to(np.array([0, 0, 1], F), (len(d), len(d), 3))
    l, v = np.broadcast_arrays(d[:, None, :], d[None, :, :])
    for w in (F(0.0), F(1e-7), F(0.5), F(1.0)):
        for alpha in (F(0.0), F(1e-4), F(1.0)):
            with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
                direction, mu_w = diffuse.wrapped_light_direction(n, l, w, clamp=False)
                value = diffuse.cod_wrapped_diffuse_cosine(F(1.0), n, v, l, alpha, w)
            assert value.dtype == direction.dtype == mu_w.dtype == np.float32
            assert np.all(np.isfinite(value)) and np.all(np.isfinite(direction)) and np.all(value >= 0)


def test_wrapped_normal_float32_degenerate():
    n = np.array([[0, 0, 1]] * 3, dtype=F)
    l = np.array([[0, 0, -1], [0, 0, 1], [1, 0, 0]], dtype=F)
    with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
        out = diffuse.wrapped_normal(n, l, np.array([1.0, 1.0, 0.5], dtype=F))
    assert out.dtype == np.float32 and np.allclose(np.linalg.norm(out, axis=-1), 1.0)
