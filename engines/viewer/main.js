// The viewer page: loads the bundle named by ?scene=, draws it with the bundle's camera, lets the user orbit, change
// the exposure, each object's material inputs and each light's power.  window.rtlViewerRender() returns the
// unmodified first frame as numbers (the browser tests).
import { BundleRenderer, bundleCamera, loadBundle, orbitCamera } from './viewer.js';

const status = document.getElementById( 'status' );
const canvas = document.getElementById( 'view' );
const scene = new URLSearchParams( location.search ).get( 'scene' );

// the float target shown on the canvas: exposure, clamp, sRGB (display only; the read-back is linear radiance)
const DISPLAY_VERTEX = `#version 300 es
out vec2 uv;
void main() { vec2 p = vec2( ( gl_VertexID & 1 ) * 2, gl_VertexID & 2 ); uv = p; gl_Position = vec4( p * 2.0 - 1.0, 0.0, 1.0 ); }`;
const DISPLAY_FRAGMENT = `#version 300 es
precision highp float;
uniform sampler2D radiance;
uniform float exposure;
in vec2 uv;
out vec4 color;
void main() {
	vec3 c = clamp( texture( radiance, uv ).rgb * exposure, 0.0, 1.0 );
	color = vec4( mix( c * 12.92, 1.055 * pow( c, vec3( 1.0 / 2.4 ) ) - 0.055, step( 0.0031308, c ) ), 1.0 );
}`;

function displayProgram( gl ) {

	const program = gl.createProgram();
	for ( const [ type, source ] of [ [ gl.VERTEX_SHADER, DISPLAY_VERTEX ], [ gl.FRAGMENT_SHADER, DISPLAY_FRAGMENT ] ] ) {

		const shader = gl.createShader( type );
		gl.shaderSource( shader, source );
		gl.compileShader( shader );
		gl.attachShader( program, shader );

	}

	gl.linkProgram( program );
	return program;

}

function slider( parent, label, min, max, value, onInput ) {

	const el = document.createElement( 'label' );
	el.textContent = label;
	const input = Object.assign( document.createElement( 'input' ), { type: 'range', min, max, step: ( max - min ) / 200, value } );
	input.addEventListener( 'input', () => onInput( parseFloat( input.value ) ) );
	el.appendChild( input );
	parent.appendChild( el );

}

async function start() {

	if ( ! scene ) throw new Error( 'no scene: open index.html?scene=URL of a web bundle (core/export/web_scene.py)' );
	const bundle = await loadBundle( scene );
	const [ w, h ] = bundle.draw.resolution;
	canvas.width = w;
	canvas.height = h;
	const gl = canvas.getContext( 'webgl2', { antialias: false } );
	if ( ! gl ) throw new Error( 'WebGL2 is not available' );
	const renderer = new BundleRenderer( gl, bundle );
	const display = displayProgram( gl );
	const state = { yaw: 0, pitch: 0, dolly: 1, exposure: 1, moved: false };
	const frame = () => {

		renderer.draw( state.moved ? orbitCamera( bundle.draw, state.yaw, state.pitch, state.dolly ) : bundleCamera( bundle.draw ) );
		gl.bindFramebuffer( gl.FRAMEBUFFER, null );
		gl.viewport( 0, 0, w, h );
		gl.disable( gl.DEPTH_TEST );
		gl.useProgram( display );
		gl.activeTexture( gl.TEXTURE0 );
		gl.bindTexture( gl.TEXTURE_2D, renderer.color );
		gl.uniform1i( gl.getUniformLocation( display, 'radiance' ), 0 );
		gl.uniform1f( gl.getUniformLocation( display, 'exposure' ), state.exposure );
		gl.drawArrays( gl.TRIANGLE_STRIP, 0, 4 );

	};

	// controls: exposure, each light's power (a factor on every object's copy), each object's float material inputs
	document.getElementById( 'exposure' ).addEventListener( 'input', ( e ) => { state.exposure = 2 ** parseFloat( e.target.value ); frame(); } );
	const controls = document.getElementById( 'controls' );
	for ( const light of bundle.draw.lights.filter( ( l ) => l.uniform ) ) {

		const base = renderer.objects.map( ( o ) => o.uniforms[ light.uniform ] );
		slider( controls, `${light.name} (${light.kind}) power x`, 0, 4, 1, ( k ) => {

			renderer.objects.forEach( ( o, i ) => { if ( light.uniform in o.uniforms ) o.uniforms[ light.uniform ] = base[ i ] * k; } );
			frame();

		} );

	}

	for ( const object of renderer.objects ) {

		const info = bundle.draw.programs[ object.program ];
		for ( const u of info.uniforms.filter( ( u ) => u.type === 'float' && typeof object.uniforms[ u.name ] === 'number' ) ) {

			const value = object.uniforms[ u.name ];
			slider( controls, `${object.name}: ${u.meaning.split( ':' )[ 0 ]}`, 0, Math.max( 1, 2 * value ), value, ( v ) => { object.uniforms[ u.name ] = v; frame(); } );

		}

	}

	let drag = null;
	canvas.addEventListener( 'pointerdown', ( e ) => { drag = [ e.clientX, e.clientY ]; canvas.setPointerCapture( e.pointerId ); } );
	canvas.addEventListener( 'pointerup', () => { drag = null; } );
	canvas.addEventListener( 'pointermove', ( e ) => {

		if ( ! drag ) return;
		state.yaw -= ( e.clientX - drag[ 0 ] ) * 0.01;
		state.pitch = Math.max( - 1.5, Math.min( 1.5, state.pitch - ( e.clientY - drag[ 1 ] ) * 0.01 ) );
		drag = [ e.clientX, e.clientY ];
		state.moved = true;
		frame();

	} );
	canvas.addEventListener( 'wheel', ( e ) => { e.preventDefault(); state.dolly *= Math.exp( e.deltaY * 0.001 ); state.moved = true; frame(); } );
	frame();
	// the first frame, as numbers: the bundle's own camera, nothing changed
	window.rtlViewerRender = () => {

		renderer.draw( bundleCamera( bundle.draw ) );
		const pixels = renderer.read();
		frame();
		const bytes = new Uint8Array( pixels.buffer );
		let text = '';
		for ( let i = 0; i < bytes.length; i += 0x8000 ) text += String.fromCharCode.apply( null, bytes.subarray( i, i + 0x8000 ) );
		return { width: w, height: h, pixels: btoa( text ), renderer: gl.getParameter( gl.RENDERER ) };

	};

	window.rtlReady = true;

}

start().catch( ( e ) => {

	status.textContent = String( e.message || e );
	console.error( String( e.message || e ) );
	window.rtlReady = true;

} );
