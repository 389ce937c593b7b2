// Headless Chromium for the RT Lookdev three.js tests: a static server for this package (and an optional data
// folder at /data/) on loopback, and Debian's chromium driven by playwright-core.  Nothing is downloaded: the
// browser is the system's (CHROMIUM, default /usr/bin/chromium), WebGL2 runs on SwiftShader.
import { createServer } from 'node:http';
import { existsSync, statSync, createReadStream } from 'node:fs';
import { join, normalize, resolve, extname, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const PACKAGE_ROOT = resolve( dirname( fileURLToPath( import.meta.url ) ), '..' );
/** The scene viewer (engines/viewer), served at /viewer/. */
export const VIEWER_ROOT = resolve( PACKAGE_ROOT, '..', 'viewer' );
export const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';

const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.json': 'application/json',
	'.exr': 'application/octet-stream', '.f32': 'application/octet-stream', '.bin': 'application/octet-stream',
	'.vert': 'text/plain', '.frag': 'text/plain', '.ktx2': 'application/octet-stream', '.glsl': 'text/plain' };

// Chromium (a fresh temporary profile per launch, playwright's default) as root in a sandboxless container, with nothing reaching out to the network (the machine's network is
// closed: background services would fail their lookups at every start).
const CHROMIUM_ARGS = [ '--headless=new', '--no-sandbox', '--disable-quic', '--no-first-run',
	'--disable-background-networking', '--disable-component-update', '--disable-sync', '--disable-dev-shm-usage',
	'--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist' ];

function serveFile( root, prefix, url, res ) {

	const rel = decodeURIComponent( url.slice( prefix.length ) );
	const path = normalize( join( root, rel ) );
	if ( ! path.startsWith( root ) || ! existsSync( path ) || ! statSync( path ).isFile() ) return false;
	res.writeHead( 200, { 'Content-Type': TYPES[ extname( path ) ] || 'application/octet-stream' } );
	createReadStream( path ).pipe( res );
	return true;

}

/** Serves PACKAGE_ROOT at /, VIEWER_ROOT at /viewer/ and `dataDir` (if given) at /data/; resolves to { url, close }. */
export function startServer( dataDir = null ) {

	const data = dataDir ? resolve( dataDir ) : null;
	const server = createServer( ( req, res ) => {

		const url = req.url.split( '?' )[ 0 ];
		const ok = ( data && url.startsWith( '/data/' ) ) ? serveFile( data, '/data/', url, res )
			: url.startsWith( '/viewer/' ) ? serveFile( VIEWER_ROOT, '/viewer/', url, res ) : serveFile( PACKAGE_ROOT, '/', url, res );
		if ( ! ok ) {

			res.writeHead( 404 );
			res.end( 'not found' );

		}

	} );
	return new Promise( ( ok ) => server.listen( 0, '127.0.0.1', () => ok( {
		url: `http://127.0.0.1:${server.address().port}`, close: () => new Promise( ( done ) => server.close( done ) ) } ) ) );

}

/** Opens `page` (a path under the package) in headless Chromium; resolves to { page, close }. */
export async function openPage( pagePath, { dataDir = null, timeout = 120000 } = {} ) {

	if ( ! existsSync( CHROMIUM ) ) throw new Error( `no Chromium at ${CHROMIUM} (Debian: apt-get install chromium; or set CHROMIUM)` );
	const server = await startServer( dataDir );
	const browser = await chromium.launch( { executablePath: CHROMIUM, args: CHROMIUM_ARGS } );
	const page = await browser.newPage();
	const errors = [];
	page.on( 'pageerror', ( e ) => errors.push( String( e ) ) );
	page.on( 'console', ( m ) => { if ( m.type() === 'error' ) errors.push( m.text() ); } );
	page.setDefaultTimeout( timeout );
	await page.goto( `${server.url}${pagePath}` );
	try {

		await page.waitForFunction( () => window.rtlReady === true );

	} catch ( e ) {

		throw new Error( `${pagePath} did not load: ${errors.join( '; ' ) || e}` );

	}

	return { page, errors, close: async () => {

		await browser.close();
		await server.close();

	} };

}
