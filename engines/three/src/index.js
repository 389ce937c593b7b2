// RT Lookdev for three.js: the project's exported LTC tables in place of three's own (issue 32).
//
// three.js shades a RectAreaLight with the linearly transformed cosines of Heitz, Dupuy, Hill & Neubelt 2016
// ("Real-Time Polygonal-Light Shading with Linearly Transformed Cosines"), reading two 64 x 64 RGBA tables laid out
// as selfshadow/ltc_code's `ltc_1` (the inverse matrix's four free entries) and `ltc_2` (magnitude, Fresnel term,
// 0, horizon-clipped sphere factor), from `UniformsLib.LTC_FLOAT_1/2` (or `LTC_HALF_1/2` where float textures
// cannot be filtered).  The export's `ltc_code` layout (python scripts/export_luts.py --layout ltc_code; layout and
// row order in docs/luts.md) holds the same channels, axes and texel centres, so installing it is a swap of the
// four textures.  Where RT Lit uses its GGX band (r >= 0.65) the layout holds the best single LTC instead.
import {
	ClampToEdgeWrapping,
	DataTexture,
	FloatType,
	HalfFloatType,
	LinearFilter,
	RGBAFormat,
	UniformsLib,
	UVMapping,
} from 'three';

/** The table files of the export's `ltc_code` layout that three's RectAreaLight reads. */
export const LTC_TABLE_FILES = Object.freeze( { ltc1: 'ltc_1', ltc2: 'ltc_2' } );

/** Side of the LTC tables, in texels (three's `LTC_Uv` assumes 64). */
export const LTC_SIZE = 64;

function checkTable( name, data ) {

	const expected = LTC_SIZE * LTC_SIZE * 4;
	if ( ! ( data instanceof Float32Array || data instanceof Uint16Array ) ) {

		throw new TypeError( `RT Lookdev: table ${name} must be a Float32Array (float) or a Uint16Array (half float bits), got ${Object.prototype.toString.call( data )}` );

	}

	if ( data.length !== expected ) {

		throw new RangeError( `RT Lookdev: table ${name} has ${data.length} values; a ${LTC_SIZE} x ${LTC_SIZE} RGBA table has ${expected}` );

	}

}

/**
 * A DataTexture of one LTC table, data row t = 0 first (the order of three's own tables and of the export's
 * `v_ascending` files; an EXR read by EXRLoader arrives in this order too).  Bilinear for both magnification and
 * minification: three's own tables use nearest for minification, which snaps to texels wherever the lookup
 * coordinate changes faster than a texel per pixel.
 *
 * @param {Float32Array|Uint16Array} data - 64 x 64 x RGBA values (float) or half-float bits.
 * @return {DataTexture}
 */
export function ltcTexture( data, name = 'table' ) {

	checkTable( name, data );
	const type = data instanceof Float32Array ? FloatType : HalfFloatType;
	const texture = new DataTexture( data, LTC_SIZE, LTC_SIZE, RGBAFormat, type, UVMapping,
		ClampToEdgeWrapping, ClampToEdgeWrapping, LinearFilter, LinearFilter, 1 );
	texture.name = `rt_lookdev_${name}`;
	texture.needsUpdate = true;
	return texture;

}

/**
 * Puts the given LTC pair in place of three's own, for every WebGLRenderer of this three module.
 *
 * Call it before the first render of a scene with a RectAreaLight, instead of (or after)
 * `RectAreaLightUniformsLib.init()`.  Both of three's slots (float and half) get the pair, so the renderer reads it
 * whichever it picks.  Materials compiled before the call keep the textures they had until their next
 * `needsUpdate`.
 *
 * @param {WebGLRenderer|null} renderer - the renderer that will draw (kept for symmetry with other installers; the
 *     tables live in three's module-wide `UniformsLib`); may be null.
 * @param {{tables: {ltc1: (DataTexture|Float32Array|Uint16Array), ltc2: (DataTexture|Float32Array|Uint16Array)}}} options
 * @return {{ltc1: DataTexture, ltc2: DataTexture}} the installed textures.
 */
export function installRtLookdev( renderer, { tables } = {} ) {

	if ( ! tables || ! tables.ltc1 || ! tables.ltc2 ) {

		throw new TypeError( 'RT Lookdev: installRtLookdev(renderer, { tables: { ltc1, ltc2 } }) needs both tables (see loadRtLookdevTables)' );

	}

	if ( renderer && renderer.properties === undefined ) {

		throw new TypeError( 'RT Lookdev: the first argument must be a WebGLRenderer (or null)' );

	}

	const ltc1 = tables.ltc1.isDataTexture ? tables.ltc1 : ltcTexture( tables.ltc1, 'ltc_1' );
	const ltc2 = tables.ltc2.isDataTexture ? tables.ltc2 : ltcTexture( tables.ltc2, 'ltc_2' );
	UniformsLib.LTC_FLOAT_1 = ltc1;
	UniformsLib.LTC_FLOAT_2 = ltc2;
	UniformsLib.LTC_HALF_1 = ltc1;
	UniformsLib.LTC_HALF_2 = ltc2;

	return { ltc1, ltc2 };

}

/**
 * Loads the export's `ltc_code` pair (`ltc_1_<precision>.exr`, `ltc_2_<precision>.exr`) from a folder URL.
 *
 * The EXRs are `v_descending` (docs/luts.md); three's EXRLoader writes scanline y to row H - 1 - y, so the data
 * arrive with table row t = 0 first, as three's tables are.
 *
 * @param {string} baseUrl - the export folder, e.g. 'luts/ltc_code/'.
 * @param {{precision?: ('f32'|'f16'), EXRLoader: Function}} options - EXRLoader from 'three/addons/loaders/EXRLoader.js'.
 * @return {Promise<{ltc1: DataTexture, ltc2: DataTexture}>}
 */
export async function loadRtLookdevTables( baseUrl, { precision = 'f32', EXRLoader } = {} ) {

	if ( precision !== 'f32' && precision !== 'f16' ) {

		throw new RangeError( `RT Lookdev: precision must be 'f32' or 'f16', got ${precision}` );

	}

	if ( typeof EXRLoader !== 'function' ) {

		throw new TypeError( "RT Lookdev: pass { EXRLoader } (import { EXRLoader } from 'three/addons/loaders/EXRLoader.js')" );

	}

	const base = baseUrl.endsWith( '/' ) ? baseUrl : baseUrl + '/';
	const type = precision === 'f32' ? FloatType : HalfFloatType;
	const out = {};
	for ( const [ key, stem ] of Object.entries( LTC_TABLE_FILES ) ) {

		const url = `${base}${stem}_${precision}.exr`;
		const response = await fetch( url );
		if ( ! response.ok ) throw new Error( `RT Lookdev: ${url}: HTTP ${response.status}` );
		const parsed = new EXRLoader().setDataType( type ).parse( await response.arrayBuffer() );
		if ( parsed.width !== LTC_SIZE || parsed.height !== LTC_SIZE ) {

			throw new RangeError( `RT Lookdev: ${url} is ${parsed.width} x ${parsed.height}, not ${LTC_SIZE} x ${LTC_SIZE}` );

		}

		out[ key ] = ltcTexture( parsed.data, stem );

	}

	return out;

}

export { patchAreaLights, loadRtLitTables, RTL_AREA_TABLES } from './patch.js';
