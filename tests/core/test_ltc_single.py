"""The standalone GGX LTC (issue 32; docs/luts.md, ``ltc_ggx_single``): ltc_ggx's lobe fitted as one LTC in every
column, the GGX pair of the export's ltc_code layout.  Below the band it is ltc_ggx to the bit; in the band's columns it
is closer to the lobe on its own than ltc_ggx's base fit read without its band."""
import numpy as np
import pytest

from rt_lookdev.core.ltc import fit
from rt_lookdev.core.ltc import fit_lobes as lobes
from rt_lookdev.core.lut import catalog, lookup

BAND = catalog.LTC_BANDS["ltc_ggx"]
FIRST_BAND_COLUMN = int(np.ceil(BAND["min_roughness"] * (catalog.LTC_SIZE - 1)))      # 41: r = 0.651


@pytest.fixture(scope="module")
def tables(lut_dir):
    return lookup.LutSet.from_folder(lut_dir)


def test_single_is_ltc_ggx_below_the_band_and_refitted_in_it(tables):
    assert catalog.GROUPS["ltc_ggx_single"].params == {k: v for k, v in catalog.GROUPS["ltc_ggx"].params.items()
                                                       if k != "band"}
    for kind in ("inv", "mag"):
        single, banded = tables.array(f"ltc_ggx_single_{kind}"), tables.array(f"ltc_ggx_{kind}")
        assert single[:, :FIRST_BAND_COLUMN].tobytes() == banded[:, :FIRST_BAND_COLUMN].tobytes()
    single, banded = tables.array("ltc_ggx_single_inv"), tables.array("ltc_ggx_inv")
    assert (np.abs(single - banded)[:, FIRST_BAND_COLUMN:].max(axis=(0, 2)) > 1e-3).all()   # every band column refitted
    assert not tables.array("ltc_ggx_single_mag")[..., 2].any()                            # no band: B = 0
    np.testing.assert_array_equal(tables.array("ltc_ggx_single_mag")[..., [0, 1, 3]],
                                  tables.array("ltc_ggx_mag")[..., [0, 1, 3]])              # same lobe integrals


def test_single_fit_beats_the_band_base_read_alone(tables):
    """The TV distance (fit.tv_distance: the bound on the error over any light, relative to the albedo) of the single LTC
    against ltc_ggx's base LTC read without its band, at the band's columns (r = 0.65 ... 1) and four view rows."""
    lobe = lobes.LOBES["ggx"]
    cols = np.array([FIRST_BAND_COLUMN, 48, 56, 63])
    r = cols / (catalog.LTC_SIZE - 1)
    for t in (0, 20, 40, 56):
        mu = max(1.0 - (t / (catalog.LTC_SIZE - 1)) ** 2, fit.FIT_MU_MIN)
        magnitude = tables.array("ltc_ggx_single_mag")[t, cols, 0].astype(np.float64)
        single = fit.tv_distance(lobe, mu, r, magnitude, tables.array("ltc_ggx_single_inv")[t, cols].astype(np.float64),
                                 n=1 << 12)
        base = fit.tv_distance(lobe, mu, r, magnitude, tables.array("ltc_ggx_inv")[t, cols].astype(np.float64), n=1 << 12)
        assert (single < base).all(), (t, single, base)
