// Renders the cases of a JSON spec with three.js in headless Chromium and writes the read-back numbers as JSON.
//
//   node tools/render_cases.mjs --spec SPEC.json --data EXPORT_DIR --out RESULT.json
//
// SPEC is what harness/harness.js' `rtlRender` takes (its comment says the fields), plus `loadTables` (a list of
// precisions whose pair is also returned as loadRtLookdevTables reads it); EXPORT_DIR, served at /data/, holds the
// `ltc_code` layout's EXRs in ltc_code/ and the `rtl` layout's f32 EXRs in rtl/ (python scripts/export_luts.py
// --layout ... --formats exr; validation/harness/three_browser.export_tables writes both).  Used by the
// Python side of the project's tests and benchmarks (validation/harness/three_browser.py).
import { readFileSync, writeFileSync } from 'node:fs';
import { parseArgs } from 'node:util';
import { openPage } from './browser.mjs';

const { values: args } = parseArgs( { options: { spec: { type: 'string' }, data: { type: 'string' }, out: { type: 'string' } } } );
if ( ! args.spec || ! args.out ) {

	console.error( 'usage: node tools/render_cases.mjs --spec SPEC.json [--data EXPORT_DIR] --out RESULT.json' );
	process.exit( 2 );

}

const spec = JSON.parse( readFileSync( args.spec, 'utf8' ) );
spec.dataUrl = spec.dataUrl || '/data/ltc_code/';
spec.rtlUrl = spec.rtlUrl || '/data/rtl/';
const t0 = performance.now();
const session = await openPage( '/harness/index.html', { dataDir: args.data } );
try {

	const result = await session.page.evaluate( ( s ) => window.rtlRender( s ), spec );
	if ( spec.loadTables ) {

		result.tables = {};
		for ( const precision of spec.loadTables ) result.tables[ precision ] = await session.page.evaluate( ( [ u, p ] ) => window.rtlLoadTables( u, p ), [ spec.dataUrl, precision ] );

	}

	result.seconds = ( performance.now() - t0 ) / 1000;
	result.errors = session.errors;
	writeFileSync( args.out, JSON.stringify( result ) );

} finally {

	await session.close();

}
