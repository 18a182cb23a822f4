// tests/js/validate_gltf.js — Khronos' glTF validator (the npm build of
// KhronosGroup/glTF-Validator, pinned in package.json) on one .glb or .gltf
// file: prints its JSON report on stdout, exits 0 when it found no errors,
// 1 when it did, 2 when it could not run.
//   node tests/js/validate_gltf.js FILE
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

const file = process.argv[2];
if (!file) {
  console.error('usage: node validate_gltf.js FILE');
  process.exit(2);
}
const bytes = new Uint8Array(fs.readFileSync(file));
validator.validateBytes(bytes, {
  uri: path.basename(file),
  maxIssues: 100,
  // a .gltf's external buffers beside it; a .glb holds its own
  externalResourceFunction: (uri) =>
    new Promise((resolve, reject) => {
      fs.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
        err ? reject(err.toString()) : resolve(new Uint8Array(data)));
    }),
}).then((report) => {
  process.stdout.write(JSON.stringify(report) + '\n');
  process.exit(report.issues.numErrors > 0 ? 1 : 0);
}).catch((err) => {
  console.error(String(err));
  process.exit(2);
});
