// Browser side of the RT Lookdev three.js tests: renders a metallic plane under a RectAreaLight into a float
// target with a chosen LTC table pair and returns the pixels and their world positions (read back as numbers).
// Driven by tools/render_cases.mjs (playwright-core, headless Chromium); the truth is computed by the caller.
import * as THREE from 'three';
import { RectAreaLightTexturesLib } from 'three/addons/lights/RectAreaLightTexturesLib.js';
import { RectAreaLightUniformsLib } from 'three/addons/lights/RectAreaLightUniformsLib.js';
import { EXRLoader } from 'three/addons/loaders/EXRLoader.js';
import { installRtLookdev, loadRtLitTables, loadRtLookdevTables, ltcTexture, patchAreaLights } from 'rt-lookdev-three';

const PLANE_SIDE = 200;

function toBase64( typed ) {

	const bytes = new Uint8Array( typed.buffer, typed.byteOffset, typed.byteLength );
	let s = '';
	for ( let i = 0; i < bytes.length; i += 0x8000 ) s += String.fromCharCode.apply( null, bytes.subarray( i, i + 0x8000 ) );
	return btoa( s );

}

// The table pairs a case can name.  'three' / 'three_half' are three's own data installed the same way as ours
// (same texture settings), so that only the numbers differ; 'three_stock' is three's own setup untouched.
async function tablePairs( names, dataUrl ) {

	RectAreaLightTexturesLib.init();
	const lib = RectAreaLightTexturesLib;
	const out = {};
	for ( const name of names ) {

		if ( name === 'three' ) out[ name ] = { ltc1: ltcTexture( lib.LTC_FLOAT_1.image.data, 'three_1' ), ltc2: ltcTexture( lib.LTC_FLOAT_2.image.data, 'three_2' ) };
		else if ( name === 'three_half' ) out[ name ] = { ltc1: ltcTexture( lib.LTC_HALF_1.image.data, 'three_half_1' ), ltc2: ltcTexture( lib.LTC_HALF_2.image.data, 'three_half_2' ) };
		else if ( name === 'three_stock' ) out[ name ] = null;
		else if ( name === 'rtl_f32' || name === 'rtl_f16' ) out[ name ] = await loadRtLookdevTables( dataUrl, { precision: name.slice( 4 ), EXRLoader } );
		else throw new Error( `unknown table pair ${name}` );

	}

	return out;

}

function makeCamera( spec ) {

	const camera = new THREE.PerspectiveCamera( spec.fov, 1, 0.01, 1000 );
	camera.up.set( 0, 0, 1 );
	camera.position.fromArray( spec.position );
	camera.lookAt( new THREE.Vector3().fromArray( spec.target ) );
	camera.updateMatrixWorld( true );
	return camera;

}

function makeLight( spec ) {

	const light = new THREE.RectAreaLight( 0xffffff, 1, spec.width, spec.height );
	if ( spec.up ) light.up.fromArray( spec.up );
	light.position.fromArray( spec.position );
	light.lookAt( new THREE.Vector3().fromArray( spec.target ) );
	light.updateMatrixWorld( true );
	return light;

}

// The corners three shades (WebGLLights + RE_Direct_RectArea_Physical), in world space, counter-clockwise as three
// orders them: position + hw - hh, - hw - hh, - hw + hh, + hw + hh.
function lightCorners( light ) {

	const hw = new THREE.Vector3( light.width * 0.5, 0, 0 ), hh = new THREE.Vector3( 0, light.height * 0.5, 0 );
	const corners = [ [ 1, - 1 ], [ - 1, - 1 ], [ - 1, 1 ], [ 1, 1 ] ];
	return corners.map( ( [ a, b ] ) => light.localToWorld( hw.clone().multiplyScalar( a ).add( hh.clone().multiplyScalar( b ) ) ).toArray() );

}

const positionMaterial = new THREE.ShaderMaterial( {
	glslVersion: THREE.GLSL3,
	vertexShader: `out vec3 vWorld; void main() { vec4 w = modelMatrix * vec4( position, 1.0 ); vWorld = w.xyz; gl_Position = projectionMatrix * viewMatrix * w; }`,
	fragmentShader: `in vec3 vWorld; layout(location = 0) out vec4 outColor; void main() { outColor = vec4( vWorld, 1.0 ); }`,
} );

function readTarget( renderer, target, size ) {

	const pixels = new Float32Array( size * size * 4 );
	renderer.readRenderTargetPixels( target, 0, 0, size, size, pixels );
	return pixels;

}

function channel( pixels, c ) {

	const out = new Float32Array( pixels.length / 4 );
	for ( let i = 0; i < out.length; i ++ ) out[ i ] = pixels[ 4 * i + c ];
	return out;

}

// spec: { size, roughness: [...], tables: [...], dataUrl, configs: [{ camera: {position, target, fov}, light:
// {position, target, width, height, up?} }], patched?: [{ name, params, patch }], rtlUrl? }.  Returns per config the
// world positions (x, y, z planes), the camera position, the light's corners and, per table pair, the red channel
// of the render at each roughness (base64 float32, in the order of spec.roughness); with `patched`, per variant the
// red channel of a MeshPhysicalMaterial(params), patched by patchAreaLights(material, patch) unless patch is null
// (three's own tables are installed for these: RectAreaLightUniformsLib.init()).
async function render( spec ) {

	const size = spec.size;
	const canvas = document.createElement( 'canvas' );
	canvas.width = canvas.height = size;
	const renderer = new THREE.WebGLRenderer( { canvas, antialias: false } );
	renderer.setPixelRatio( 1 );
	renderer.setSize( size, size, false );
	const gl = renderer.getContext();
	const debug = gl.getExtension( 'WEBGL_debug_renderer_info' );
	const info = {
		renderer: gl.getParameter( debug ? debug.UNMASKED_RENDERER_WEBGL : gl.RENDERER ), version: gl.getParameter( gl.VERSION ),
		floatLinear: !! gl.getExtension( 'OES_texture_float_linear' ), three: THREE.REVISION,
	};
	const target = new THREE.WebGLRenderTarget( size, size, { type: THREE.FloatType, format: THREE.RGBAFormat,
		minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter, depthBuffer: true } );
	const pairs = await tablePairs( spec.tables, spec.dataUrl );
	const rtlTables = spec.patched ? await loadRtLitTables( spec.rtlUrl, { EXRLoader } ) : null;
	const plane = new THREE.PlaneGeometry( PLANE_SIDE, PLANE_SIDE );
	const results = [];
	// Materials are disposed at the end, not after their draw: disposing the last user of a program deletes it, and
	// SwiftShader then compiles the same program again for the next material (seconds per draw).
	const drawn = [];
	for ( const config of spec.configs ) {

		const camera = makeCamera( config.camera );
		const light = makeLight( config.light );
		const scene = new THREE.Scene();
		scene.add( light );
		const mesh = new THREE.Mesh( plane, positionMaterial );
		scene.add( mesh );
		renderer.setRenderTarget( target );
		renderer.render( scene, camera );
		const world = readTarget( renderer, target, size );
		const out = { camera: camera.position.toArray(), corners: lightCorners( light ),
			x: toBase64( channel( world, 0 ) ), y: toBase64( channel( world, 1 ) ), z: toBase64( channel( world, 2 ) ),
			values: {} };
		for ( const name of spec.tables ) {

			if ( pairs[ name ] === null ) RectAreaLightUniformsLib.init();
			else installRtLookdev( renderer, { tables: pairs[ name ] } );
			out.values[ name ] = [];
			for ( const r of spec.roughness ) {

				// a new material per draw: its uniforms pick up the installed tables when it is first compiled
				mesh.material = new THREE.MeshStandardMaterial( { color: 0xffffff, metalness: 1, roughness: r } );
				drawn.push( mesh.material );
				renderer.render( scene, camera );
				out.values[ name ].push( toBase64( channel( readTarget( renderer, target, size ), 0 ) ) );

			}

		}

		out.patched = {};
		RectAreaLightUniformsLib.init();
		for ( const variant of spec.patched || [] ) {

			const material = new THREE.MeshPhysicalMaterial( variant.params );
			if ( variant.patch ) patchAreaLights( material, { tables: rtlTables, ...variant.patch } );
			mesh.material = material;
			drawn.push( material );
			renderer.render( scene, camera );
			out.patched[ variant.name ] = toBase64( channel( readTarget( renderer, target, size ), 0 ) );

		}

		mesh.material = positionMaterial;
		results.push( out );

	}

	renderer.setRenderTarget( null );
	for ( const material of drawn ) material.dispose();
	renderer.dispose();
	return { info, results };

}

window.rtlRender = render;

// The export's ltc_code pair as loadRtLookdevTables reads it (EXRLoader), returned as stored in the textures
// (float32 values, or half-float bits for f16), so that the caller can check the orientation and the values.
async function loadTables( dataUrl, precision ) {

	const pair = await loadRtLookdevTables( dataUrl, { precision, EXRLoader } );
	const out = {};
	for ( const [ key, texture ] of Object.entries( pair ) ) out[ key ] = { type: texture.type === THREE.FloatType ? 'float32' : 'float16', data: toBase64( texture.image.data ) };
	return out;

}

window.rtlLoadTables = loadTables;
window.rtlReady = true;
