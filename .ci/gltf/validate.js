// Validates every .glb and .gltf (with its external buffers) under the given directories with the Khronos glTF
// Validator; fails (exit 1) on any error or warning, or if there is nothing
// to validate. Usage: node validate.js DIR...
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

function glbs(dir) {
  if (!fs.existsSync(dir)) return [];
  return fs.readdirSync(dir, { withFileTypes: true }).flatMap((e) => {
    const p = path.join(dir, e.name);
    return e.isDirectory() ? glbs(p) : /\.(glb|gltf)$/.test(e.name) ? [p] : [];
  });
}

(async () => {
  const files = process.argv.slice(2).flatMap(glbs).sort();
  if (files.length === 0) {
    console.error('gltf-validator: no .glb or .gltf files found in ' + process.argv.slice(2).join(', '));
    process.exit(1);
  }
  let failed = 0;
  for (const f of files) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(f)), {
      uri: f,
      maxIssues: 50,
      externalResourceFunction: (uri) =>
        new Promise((resolve, reject) => {
          fs.readFile(path.join(path.dirname(f), decodeURIComponent(uri)), (err, data) =>
            err ? reject(err.toString()) : resolve(new Uint8Array(data)));
        }),
    });
    const { numErrors, numWarnings, numInfos, numHints } = report.issues;
    const ok = numErrors === 0 && numWarnings === 0;
    console.log(`${ok ? 'ok  ' : 'FAIL'} ${f}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints`);
    for (const m of report.issues.messages) {
      if (m.severity <= 1) console.log(`     ${m.code} ${m.pointer || ''}: ${m.message}`);
    }
    if (!ok) failed += 1;
  }
  console.log(`gltf-validator: ${files.length - failed} passed, ${failed} failed`);
  process.exit(failed === 0 ? 0 : 1);
})();
