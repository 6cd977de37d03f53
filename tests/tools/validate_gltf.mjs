// SPDX-License-Identifier: GPL-3.0-or-later
// Validates a glTF/GLB file with the Khronos glTF-Validator (npm package gltf-validator).
//   node validate_gltf.mjs NPM_PREFIX FILE.glb
// NPM_PREFIX is the directory `npm install --prefix` installed into (`make test-deps` uses
// build/node). Prints a one-line JSON summary on stdout:
//   {"errors":N,"warnings":N,"infos":N,"hints":N,"messages":["CODE at POINTER: message", ...]}
// Exit code: 0 without errors, 1 with errors, 2 when the validator or the file is missing.
import { createRequire } from 'node:module';
import fs from 'node:fs';
import path from 'node:path';

const [prefix, file] = process.argv.slice(2);
if (!prefix || !file) {
  console.error('usage: node validate_gltf.mjs NPM_PREFIX FILE.glb');
  process.exit(2);
}
let validator;
try {
  validator = createRequire(path.join(path.resolve(prefix), 'package.json'))('gltf-validator');
} catch (e) {
  console.error(`gltf-validator is not installed under ${prefix}/node_modules: run \`make test-deps\``);
  process.exit(2);
}
let bytes;
try {
  bytes = new Uint8Array(fs.readFileSync(file));
} catch (e) {
  console.error(`${file}: ${e.message}`);
  process.exit(2);
}
const report = await validator.validateBytes(bytes, {
  uri: path.basename(file),
  maxIssues: 0,  // report every issue
  // Everything lives in the GLB's binary chunk; any external reference is an error.
  externalResourceFunction: (uri) => Promise.reject(new Error(`external resource ${uri}`)),
});
const issues = report.issues;
const summary = {
  errors: issues.numErrors,
  warnings: issues.numWarnings,
  infos: issues.numInfos,
  hints: issues.numHints,
  messages: issues.messages.map((m) => `${m.code} at ${m.pointer ?? '-'}: ${m.message}`),
};
console.log(JSON.stringify(summary));
process.exit(issues.numErrors === 0 ? 0 : 1);
