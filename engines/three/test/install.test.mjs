// Unit tests of the package's installer (node --test; no browser): the textures it makes and where it puts them.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { FloatType, HalfFloatType, LinearFilter, UniformsLib } from 'three';
import { installRtLookdev, loadRtLookdevTables, ltcTexture, LTC_SIZE } from '../src/index.js';

const N = LTC_SIZE * LTC_SIZE * 4;

test( 'ltcTexture makes a 64 x 64 RGBA float or half texture, bilinear both ways', () => {

	const f = ltcTexture( new Float32Array( N ), 'a' );
	assert.equal( f.type, FloatType );
	assert.equal( f.image.width, 64 );
	assert.equal( f.minFilter, LinearFilter );
	assert.equal( f.magFilter, LinearFilter );
	assert.equal( f.flipY, false );
	assert.equal( ltcTexture( new Uint16Array( N ), 'b' ).type, HalfFloatType );

} );

test( 'ltcTexture refuses wrong sizes and types with the reason', () => {

	assert.throws( () => ltcTexture( new Float32Array( N - 4 ), 'ltc_1' ), /ltc_1 has 16380 values/ );
	assert.throws( () => ltcTexture( new Float64Array( N ), 'ltc_1' ), /Float32Array/ );
	assert.throws( () => ltcTexture( [ 1, 2, 3 ], 'ltc_1' ), /Float32Array/ );

} );

test( 'installRtLookdev puts the pair in both of three\'s slots', () => {

	const ltc1 = new Float32Array( N ).fill( 1 ), ltc2 = new Float32Array( N ).fill( 2 );
	const installed = installRtLookdev( null, { tables: { ltc1, ltc2 } } );
	for ( const slot of [ 'LTC_FLOAT_1', 'LTC_HALF_1' ] ) assert.equal( UniformsLib[ slot ], installed.ltc1 );
	for ( const slot of [ 'LTC_FLOAT_2', 'LTC_HALF_2' ] ) assert.equal( UniformsLib[ slot ], installed.ltc2 );
	assert.equal( installed.ltc1.image.data, ltc1 );

} );

test( 'installRtLookdev says what is missing', () => {

	assert.throws( () => installRtLookdev( null, {} ), /needs both tables/ );
	assert.throws( () => installRtLookdev( null, { tables: { ltc1: new Float32Array( N ) } } ), /needs both tables/ );
	assert.throws( () => installRtLookdev( {}, { tables: { ltc1: new Float32Array( N ), ltc2: new Float32Array( N ) } } ), /WebGLRenderer/ );

} );

test( 'loadRtLookdevTables checks its options before fetching', async () => {

	await assert.rejects( loadRtLookdevTables( 'x/', { precision: 'f64', EXRLoader: class {} } ), /precision/ );
	await assert.rejects( loadRtLookdevTables( 'x/', { precision: 'f32' } ), /EXRLoader/ );

} );

test( 'patchAreaLights checks the material, the options and the tables', async () => {

	const { MeshPhysicalMaterial, MeshBasicMaterial } = await import( 'three' );
	const { patchAreaLights, RTL_AREA_TABLES } = await import( '../src/index.js' );
	const tables = Object.fromEntries( Object.keys( RTL_AREA_TABLES ).map( ( name ) => [ name, {} ] ) );
	assert.throws( () => patchAreaLights( new MeshBasicMaterial(), { tables } ), /MeshStandardMaterial/ );
	assert.throws( () => patchAreaLights( new MeshPhysicalMaterial(), { tables, specular: 'kulla' } ), /specular must be one of turquin, single/ );
	assert.throws( () => patchAreaLights( new MeshPhysicalMaterial(), { tables: {} } ), /needs the tables ltc_/ );
	const material = patchAreaLights( new MeshPhysicalMaterial(), { tables, diffuse: 'lambert' } );
	assert.deepEqual( material.userData.rtLookdevArea, { specular: 'turquin', diffuse: 'lambert', sheen: 'zeltner' } );
	assert.match( material.customProgramCacheKey(), /rt-lookdev-area:turquin:lambert:zeltner/ );

} );

test( 'the patch puts its lobes in the fragment shader and binds every table', async () => {

	const { MeshPhysicalMaterial } = await import( 'three' );
	const { patchAreaLights, RTL_AREA_TABLES } = await import( '../src/index.js' );
	const tables = Object.fromEntries( Object.keys( RTL_AREA_TABLES ).map( ( name ) => [ name, { name } ] ) );
	const material = patchAreaLights( new MeshPhysicalMaterial(), { tables } );
	const shader = { uniforms: {}, fragmentShader: 'a\n#include <lights_physical_pars_fragment>\nb' };
	material.onBeforeCompile( shader, null );
	for ( const [ name, table ] of Object.entries( RTL_AREA_TABLES ) ) assert.equal( shader.uniforms[ table.uniform ].value.name, name );
	assert.match( shader.fragmentShader, /#define RE_Direct_RectArea RE_Direct_RectArea_RtLit/ );
	assert.match( shader.fragmentShader, /rtl_quad_ggx\(/ );
	assert.match( shader.fragmentShader, /rtl_turquin_compensation\(/ );

} );
