// RT Lit's area-light shading in three.js' physical materials (issue 32, item 2): an opt-in patch of
// MeshStandardMaterial / MeshPhysicalMaterial that shades each RectAreaLight with RT Lit's lobes instead of three's.
//
// What three lacks under a RectAreaLight and the patch adds (the GLSL is generated from the project's IR:
// src/generated/rt_lit_area.js, core/export/three_area.py):
// - the GGX band (RT Lit's second LTC for r >= 0.65) and exact horizon clipping (three approximates the clipped
//   integral with a sphere's form factor);
// - multiple-scattering specular, the talk's compensation 1 + F0 (1 - E) / E (Turquin 2019);
// - the talk's multiscattering (CoD) diffuse in place of Lambert;
// - Zeltner et al. 2022's sheen (three's `sheen`, `sheenColor`, `sheenRoughness`), which three has no area form of.
// Clearcoat keeps three's own rect-area code.  Other light types are untouched.
import { ClampToEdgeWrapping, DataTexture, FloatType, NearestFilter, RGBAFormat, UVMapping } from 'three';
import { RTL_AREA_FUNCTIONS, RTL_AREA_GLSL, RTL_AREA_TABLES } from './generated/rt_lit_area.js';

export { RTL_AREA_TABLES };

const SPECULAR = [ 'turquin', 'single' ];
const DIFFUSE = [ 'cod', 'lambert' ];
const SHEEN = [ 'zeltner', 'none' ];

function ident( name ) {

	const f = RTL_AREA_FUNCTIONS[ name ];
	if ( ! f ) throw new Error( `RT Lookdev: the generated library lacks ${name} (rebuild it: python scripts/build_three_area.py)` );
	return f.ident;

}

// The replacement of RE_Direct_RectArea_Physical: wiring only, every integral is a generated function.
function chunk( { specular, diffuse, sheen } ) {

	const area = '( geometryPosition, geometryNormal, geometryViewDir, p0, p1, p2, p3, rectAreaLight.position';
	return `
#if NUM_RECT_AREA_LIGHTS > 0
${RTL_AREA_GLSL}
void RE_Direct_RectArea_RtLit( const in RectAreaLight rectAreaLight, const in vec3 geometryPosition, const in vec3 geometryNormal, const in vec3 geometryViewDir, const in vec3 geometryClearcoatNormal, const in PhysicalMaterial material, inout ReflectedLight reflectedLight ) {

	// three orders the corners counter-clockwise as seen from the lit side; RT Lit's integrals take them the other way
	vec3 hw = rectAreaLight.halfWidth, hh = rectAreaLight.halfHeight;
	vec3 p0 = rectAreaLight.position + hw + hh, p1 = rectAreaLight.position - hw + hh;
	vec3 p2 = rectAreaLight.position - hw - hh, p3 = rectAreaLight.position + hw - hh;

	float scale, bias, albedo;
	${ident( 'RTL Quad GGX' )}${area}, material.roughness, scale, bias, albedo );
	vec3 specular = material.specularColorBlended * scale + material.specularF90 * bias;
${specular === 'turquin' ? `	vec3 compensation;
	${ident( 'RTL Turquin Compensation' )}( material.specularColorBlended, albedo, compensation );
	specular *= compensation;` : ''}
	reflectedLight.directSpecular += rectAreaLight.color * specular;

	float diffuse;
${diffuse === 'cod' ? `	${ident( 'RTL Quad CoD Diffuse' )}${area}, material.roughness, diffuse );` : `	diffuse = LTC_Evaluate( geometryNormal, geometryViewDir, geometryPosition, mat3( 1.0 ), vec3[ 4 ]( p3, p2, p1, p0 ) ).x;`}
	reflectedLight.directDiffuse += rectAreaLight.color * material.diffuseContribution * diffuse;

#if defined( USE_SHEEN )
${sheen === 'zeltner' ? `	float sheenValue, sheenAlbedo;
	${ident( 'RTL Quad Zeltner Sheen' )}${area}, material.sheenRoughness, sheenValue, sheenAlbedo );
	sheenSpecularDirect += rectAreaLight.color * material.sheenColor * sheenValue;` : ''}
#endif
#if defined( USE_CLEARCOAT )
	ReflectedLight unused = ReflectedLight( vec3( 0.0 ), vec3( 0.0 ), vec3( 0.0 ), vec3( 0.0 ) );
	RE_Direct_RectArea_Physical( rectAreaLight, geometryPosition, geometryNormal, geometryViewDir, geometryClearcoatNormal, material, unused );
#endif

}
#undef RE_Direct_RectArea
#define RE_Direct_RectArea RE_Direct_RectArea_RtLit
#endif
`;

}

function check( name, value, allowed ) {

	if ( ! allowed.includes( value ) ) throw new RangeError( `RT Lookdev: ${name} must be one of ${allowed.join( ', ' )}, got ${value}` );

}

/**
 * Makes `material` (a MeshStandardMaterial or MeshPhysicalMaterial) shade RectAreaLights with RT Lit's lobes.
 *
 * @param {Material} material
 * @param {{tables: Object<string, DataTexture>, specular?: ('turquin'|'single'), diffuse?: ('cod'|'lambert'),
 *     sheen?: ('zeltner'|'none')}} options - `tables`: RTL_AREA_TABLES' tables (loadRtLitTables).
 * @return {Material} the material, patched (its previous onBeforeCompile still runs, after the patch).
 */
export function patchAreaLights( material, { tables, specular = 'turquin', diffuse = 'cod', sheen = 'zeltner' } = {} ) {

	if ( ! material || ! ( material.isMeshStandardMaterial || material.isMeshPhysicalMaterial ) ) {

		throw new TypeError( 'RT Lookdev: patchAreaLights needs a MeshStandardMaterial or MeshPhysicalMaterial' );

	}

	check( 'specular', specular, SPECULAR );
	check( 'diffuse', diffuse, DIFFUSE );
	check( 'sheen', sheen, SHEEN );
	const missing = Object.keys( RTL_AREA_TABLES ).filter( ( name ) => ! tables || ! tables[ name ] );
	if ( missing.length ) throw new TypeError( `RT Lookdev: patchAreaLights needs the tables ${missing.join( ', ' )} (loadRtLitTables)` );
	const options = { specular, diffuse, sheen };
	const previous = material.onBeforeCompile;
	material.onBeforeCompile = ( shader, renderer ) => {

		for ( const [ name, table ] of Object.entries( RTL_AREA_TABLES ) ) shader.uniforms[ table.uniform ] = { value: tables[ name ] };
		shader.fragmentShader = shader.fragmentShader.replace( '#include <lights_physical_pars_fragment>',
			'#include <lights_physical_pars_fragment>\n' + chunk( options ) );
		if ( previous ) previous.call( material, shader, renderer );

	};

	const key = `rt-lookdev-area:${specular}:${diffuse}:${sheen}`;
	const previousKey = material.customProgramCacheKey.bind( material );
	material.customProgramCacheKey = () => `${previousKey()}|${key}`;
	material.userData.rtLookdevArea = options;
	material.needsUpdate = true;
	return material;

}

/**
 * Loads the tables the patch reads (RTL_AREA_TABLES) from an export of the `rtl` layout (python
 * scripts/export_luts.py --layout rtl --formats exr --precision f32): `<name>_f32.exr`, read by three's EXRLoader
 * (row t = 0 first), fetched texel by texel by the generated code.
 *
 * @param {string} baseUrl
 * @param {{EXRLoader: Function}} options - EXRLoader from 'three/addons/loaders/EXRLoader.js'.
 * @return {Promise<Object<string, DataTexture>>}
 */
export async function loadRtLitTables( baseUrl, { EXRLoader } = {} ) {

	if ( typeof EXRLoader !== 'function' ) {

		throw new TypeError( "RT Lookdev: pass { EXRLoader } (import { EXRLoader } from 'three/addons/loaders/EXRLoader.js')" );

	}

	const base = baseUrl.endsWith( '/' ) ? baseUrl : baseUrl + '/';
	const out = {};
	for ( const [ name, table ] of Object.entries( RTL_AREA_TABLES ) ) {

		const url = `${base}${name}_f32.exr`;
		const response = await fetch( url );
		if ( ! response.ok ) throw new Error( `RT Lookdev: ${url}: HTTP ${response.status}` );
		const parsed = new EXRLoader().setDataType( FloatType ).parse( await response.arrayBuffer() );
		if ( parsed.width !== table.width || parsed.height !== table.height ) {

			throw new RangeError( `RT Lookdev: ${url} is ${parsed.width} x ${parsed.height}, not ${table.width} x ${table.height}` );

		}

		const texture = new DataTexture( parsed.data, parsed.width, parsed.height, RGBAFormat, FloatType, UVMapping,
			ClampToEdgeWrapping, ClampToEdgeWrapping, NearestFilter, NearestFilter, 1 );
		texture.name = `rt_lookdev_${name}`;
		texture.needsUpdate = true;
		out[ name ] = texture;

	}

	return out;

}
