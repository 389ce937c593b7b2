"""Write the RT Lit material's shaders for an engine: GLSL 4.50, GLSL ES 3.00 and HLSL fragment and
vertex shaders, the uniform interface (interface.json) and the LUT files they sample.

    python scripts/export_shader.py --out DIR [--specular turquin] [--diffuse cod] [--sheen [zeltner]] [--cloth]
                                    [--lights quad+cone+range,disk,point,spot,sun] [--dialects glsl450,glsl300es,hlsl]
                                    [--world ENV.exr --world-table NAME] [--no-precise] [--lut-dir DIR]

Entry point of ``rt_lookdev.core.export.shaders``; ``--help`` lists the options."""
import sys

from rt_lookdev.core.export import shaders


def main(argv):
    return shaders.run_args(shaders.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
