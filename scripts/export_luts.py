"""Export the LUTs for game engines: OpenEXR, KTX 2.0, DDS, npz, a C header and GLSL / HLSL includes, in
float32 and half, in the project's layout or selfshadow/ltc_code's, with manifest.json.

    python scripts/export_luts.py --out DIR [--formats exr,ktx2,dds,npz,c,glsl,hlsl] [--precision f32,f16]
                                  [--layout rtl|ltc_code] [--lut-dir DIR] [--rebake]

Entry point of ``rt_lookdev.core.export.luts``; ``--help`` lists the options."""
import sys

from rt_lookdev.core.export import luts


def main(argv):
    return luts.run_args(luts.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
