// Draws a web bundle (core/export/web_scene.py) with the scene viewer (engines/viewer) in headless Chromium and
// writes its first frame (the bundle's camera) as JSON: { width, height, pixels: base64 RGBA float32, row 0 at the
// bottom }.
//
//   node tools/render_viewer.mjs --bundle BUNDLE_DIR --out RESULT.json
import { writeFileSync } from 'node:fs';
import { parseArgs } from 'node:util';
import { openPage } from './browser.mjs';

const { values: args } = parseArgs( { options: { bundle: { type: 'string' }, out: { type: 'string' } } } );
if ( ! args.bundle || ! args.out ) {

	console.error( 'usage: node tools/render_viewer.mjs --bundle BUNDLE_DIR --out RESULT.json' );
	process.exit( 2 );

}

const t0 = performance.now();
const session = await openPage( '/viewer/index.html?scene=/data/', { dataDir: args.bundle } );
try {

	const status = await session.page.textContent( '#status' );
	if ( status ) throw new Error( `the viewer says: ${status}` );
	const result = await session.page.evaluate( () => window.rtlViewerRender() );
	result.seconds = ( performance.now() - t0 ) / 1000;
	result.errors = session.errors;
	writeFileSync( args.out, JSON.stringify( result ) );

} finally {

	await session.close();

}
