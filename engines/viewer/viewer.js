// RT Lookdev scene viewer: draws a web bundle (core/export/web_scene.py: draw.json, geometry.bin, programs/, tables/)
// with plain WebGL2, as the standalone renderer (validation/harness/realtime_render.py) draws it on OpenGL 4.5: one
// program per feature set, world-space triangles, an RGBA32F target, tables fetched texel by texel.

export async function loadBundle( url ) {

	const base = url.endsWith( '/' ) ? url : url + '/';
	const get = async ( path, kind ) => {

		const response = await fetch( base + path );
		if ( ! response.ok ) throw new Error( `${base}${path}: HTTP ${response.status}` );
		return kind === 'json' ? response.json() : kind === 'text' ? response.text() : response.arrayBuffer();

	};

	const draw = await get( 'draw.json', 'json' );
	if ( draw.format !== 'rt-lookdev-web' || draw.version !== 1 ) throw new Error( `${base}draw.json: not an rt-lookdev-web bundle of version 1` );
	const programs = [];
	for ( const p of draw.programs ) programs.push( { ...p, vertexSource: await get( p.vertex, 'text' ), fragmentSource: await get( p.fragment, 'text' ) } );
	const tables = {};
	for ( const [ name, t ] of Object.entries( draw.tables ) ) tables[ name ] = { ...t, data: new Float32Array( await get( t.file ) ) };
	const geometry = new Float32Array( await get( 'geometry.bin' ) );
	return { draw, programs, tables, geometry };

}

function compile( gl, type, source, what ) {

	const shader = gl.createShader( type );
	gl.shaderSource( shader, source );
	gl.compileShader( shader );
	if ( ! gl.getShaderParameter( shader, gl.COMPILE_STATUS ) ) throw new Error( `${what}: ${gl.getShaderInfoLog( shader )}` );
	return shader;

}

function link( gl, p ) {

	const program = gl.createProgram();
	gl.attachShader( program, compile( gl, gl.VERTEX_SHADER, p.vertexSource, p.vertex ) );
	gl.attachShader( program, compile( gl, gl.FRAGMENT_SHADER, p.fragmentSource, p.fragment ) );
	gl.bindAttribLocation( program, 0, 'a_position' );
	gl.bindAttribLocation( program, 1, 'a_normal' );
	gl.linkProgram( program );
	if ( ! gl.getProgramParameter( program, gl.LINK_STATUS ) ) throw new Error( `${p.fragment}: ${gl.getProgramInfoLog( program )}` );
	return program;

}

function setUniform( gl, program, name, value ) {

	if ( Array.isArray( value ) && Array.isArray( value[ 0 ] ) ) {             // an array of vectors (u_world_sh)

		const location = gl.getUniformLocation( program, `${name}[0]` ) || gl.getUniformLocation( program, name );
		if ( location ) gl.uniform3fv( location, value.flat() );
		return;

	}

	const location = gl.getUniformLocation( program, name );
	if ( location === null ) return;                                            // the compiler dropped it
	if ( typeof value === 'number' ) gl.uniform1f( location, value );
	else if ( value.length === 3 ) gl.uniform3fv( location, value );
	else if ( value.length === 4 ) gl.uniform4fv( location, value );
	else if ( value.length === 9 ) gl.uniformMatrix3fv( location, false, value );
	else if ( value.length === 16 ) gl.uniformMatrix4fv( location, false, value );
	else throw new Error( `uniform ${name}: cannot set ${value.length} values` );

}

/** A renderer of one bundle on a WebGL2 context: draw( camera ) into an RGBA32F target; read() the pixels. */
export class BundleRenderer {

	constructor( gl, bundle ) {

		if ( ! gl.getExtension( 'EXT_color_buffer_float' ) ) throw new Error( 'this WebGL2 cannot render to float targets (EXT_color_buffer_float)' );
		this.gl = gl;
		this.bundle = bundle;
		this.programs = bundle.programs.map( ( p ) => link( gl, p ) );
		this.textures = {};
		for ( const [ name, t ] of Object.entries( bundle.tables ) ) {

			const texture = gl.createTexture();
			gl.bindTexture( gl.TEXTURE_2D, texture );
			gl.texImage2D( gl.TEXTURE_2D, 0, gl.RGBA32F, t.width, t.height, 0, gl.RGBA, gl.FLOAT, t.data );
			for ( const p of [ gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER ] ) gl.texParameteri( gl.TEXTURE_2D, p, gl.NEAREST );
			for ( const p of [ gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T ] ) gl.texParameteri( gl.TEXTURE_2D, p, gl.CLAMP_TO_EDGE );
			this.textures[ name ] = texture;

		}

		this.vao = gl.createVertexArray();
		gl.bindVertexArray( this.vao );
		const buffer = gl.createBuffer();
		gl.bindBuffer( gl.ARRAY_BUFFER, buffer );
		gl.bufferData( gl.ARRAY_BUFFER, bundle.geometry, gl.STATIC_DRAW );
		gl.enableVertexAttribArray( 0 );
		gl.vertexAttribPointer( 0, 3, gl.FLOAT, false, 24, 0 );
		gl.enableVertexAttribArray( 1 );
		gl.vertexAttribPointer( 1, 3, gl.FLOAT, false, 24, 12 );
		const [ w, h ] = bundle.draw.resolution;
		this.resize( w, h );
		// per object: its uniform values, editable by the controls (a copy of the bundle's)
		this.objects = bundle.draw.objects.map( ( o ) => ( { ...o, uniforms: { ...o.uniforms } } ) );

	}

	resize( w, h ) {

		const gl = this.gl;
		this.width = w;
		this.height = h;
		this.color = gl.createTexture();
		gl.bindTexture( gl.TEXTURE_2D, this.color );
		gl.texImage2D( gl.TEXTURE_2D, 0, gl.RGBA32F, w, h, 0, gl.RGBA, gl.FLOAT, null );
		for ( const p of [ gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER ] ) gl.texParameteri( gl.TEXTURE_2D, p, gl.NEAREST );
		const depth = gl.createRenderbuffer();
		gl.bindRenderbuffer( gl.RENDERBUFFER, depth );
		gl.renderbufferStorage( gl.RENDERBUFFER, gl.DEPTH_COMPONENT32F, w, h );
		this.fbo = gl.createFramebuffer();
		gl.bindFramebuffer( gl.FRAMEBUFFER, this.fbo );
		gl.framebufferTexture2D( gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, this.color, 0 );
		gl.framebufferRenderbuffer( gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth );
		if ( gl.checkFramebufferStatus( gl.FRAMEBUFFER ) !== gl.FRAMEBUFFER_COMPLETE ) throw new Error( 'the float target is incomplete' );

	}

	/** Draws every object with `camera` ({ viewProjection (column-major 16), position, forward, orthographic }). */
	draw( camera ) {

		const gl = this.gl;
		gl.bindFramebuffer( gl.FRAMEBUFFER, this.fbo );
		gl.viewport( 0, 0, this.width, this.height );
		gl.enable( gl.DEPTH_TEST );
		gl.disable( gl.CULL_FACE );
		gl.clearColor( 0, 0, 0, 0 );
		gl.clearDepth( 1 );
		gl.clear( gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT );
		gl.bindVertexArray( this.vao );
		const identity3 = [ 1, 0, 0, 0, 1, 0, 0, 0, 1 ], identity4 = [ 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 ];
		for ( const object of this.objects ) {

			const program = this.programs[ object.program ];
			const info = this.bundle.draw.programs[ object.program ];
			gl.useProgram( program );
			for ( const [ name, value ] of Object.entries( object.uniforms ) ) setUniform( gl, program, name, value );
			setUniform( gl, program, 'u_camera_position', camera.position );
			setUniform( gl, program, 'u_camera_forward', camera.forward );
			setUniform( gl, program, 'u_camera_orthographic', camera.orthographic ? 1 : 0 );
			setUniform( gl, program, 'u_view_projection', camera.viewProjection );
			setUniform( gl, program, 'u_model', identity4 );
			setUniform( gl, program, 'u_normal_matrix', identity3 );
			let unit = 0;
			for ( const [ uniform, table ] of Object.entries( info.textures ) ) {

				gl.activeTexture( gl.TEXTURE0 + unit );
				gl.bindTexture( gl.TEXTURE_2D, this.textures[ table ] );
				const location = gl.getUniformLocation( program, uniform );
				if ( location ) gl.uniform1i( location, unit );
				unit ++;

			}

			gl.drawArrays( gl.TRIANGLES, object.first, object.count );

		}

	}

	/** The target's pixels, RGBA float32, row 0 at the bottom (OpenGL's order). */
	read() {

		const gl = this.gl;
		const pixels = new Float32Array( this.width * this.height * 4 );
		gl.bindFramebuffer( gl.FRAMEBUFFER, this.fbo );
		gl.readPixels( 0, 0, this.width, this.height, gl.RGBA, gl.FLOAT, pixels );
		return pixels;

	}

}

// --- camera: the bundle's, and an orbit about a point in front of it ----------------------------------------------

export function multiply( a, b ) {                       // column-major 4 x 4

	const out = new Array( 16 ).fill( 0 );
	for ( let c = 0; c < 4; c ++ ) for ( let r = 0; r < 4; r ++ ) for ( let k = 0; k < 4; k ++ ) out[ c * 4 + r ] += a[ k * 4 + r ] * b[ c * 4 + k ];
	return out;

}

export function bundleCamera( draw ) {

	const c = draw.camera;
	return { viewProjection: multiply( c.projection, c.view ), position: c.position, forward: c.forward, orthographic: c.orthographic };

}

/** The bundle's camera turned by `yaw` about world +Z and `pitch` about its right axis, around the point `distance`
 * in front of it, then moved `dolly` times closer.  Blender's camera frame: it looks along -Z with +Y up. */
export function orbitCamera( draw, yaw, pitch, dolly = 1 ) {

	const c = draw.camera;
	const sub = ( a, b ) => a.map( ( v, i ) => v - b[ i ] ), add = ( a, b ) => a.map( ( v, i ) => v + b[ i ] );
	const scale = ( a, s ) => a.map( ( v ) => v * s ), dot = ( a, b ) => a.reduce( ( s, v, i ) => s + v * b[ i ], 0 );
	const cross = ( a, b ) => [ a[ 1 ] * b[ 2 ] - a[ 2 ] * b[ 1 ], a[ 2 ] * b[ 0 ] - a[ 0 ] * b[ 2 ], a[ 0 ] * b[ 1 ] - a[ 1 ] * b[ 0 ] ];
	const norm = ( a ) => scale( a, 1 / Math.hypot( ...a ) );
	const distance = Math.max( Math.hypot( ...c.position ), 1e-3 );
	const target = add( c.position, scale( c.forward, distance ) );
	let offset = sub( c.position, target );
	const rotZ = ( v, a ) => [ v[ 0 ] * Math.cos( a ) - v[ 1 ] * Math.sin( a ), v[ 0 ] * Math.sin( a ) + v[ 1 ] * Math.cos( a ), v[ 2 ] ];
	offset = rotZ( offset, yaw );
	const right = norm( cross( offset, [ 0, 0, 1 ] ) );
	const along = ( v, k, a ) => add( add( scale( v, Math.cos( a ) ), scale( cross( k, v ), Math.sin( a ) ) ), scale( k, dot( k, v ) * ( 1 - Math.cos( a ) ) ) );
	offset = scale( along( offset, right, pitch ), dolly );
	const eye = add( target, offset );
	const back = norm( offset ), side = norm( cross( [ 0, 0, 1 ], back ) ), up = cross( back, side );
	const view = [ side[ 0 ], up[ 0 ], back[ 0 ], 0, side[ 1 ], up[ 1 ], back[ 1 ], 0, side[ 2 ], up[ 2 ], back[ 2 ], 0,
		- dot( side, eye ), - dot( up, eye ), - dot( back, eye ), 1 ];
	return { viewProjection: multiply( c.projection, view ), position: eye, forward: scale( back, - 1 ), orthographic: c.orthographic };

}
