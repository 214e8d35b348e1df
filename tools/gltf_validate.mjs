#!/usr/bin/env node
// Validates glTF/GLB files with the Khronos glTF validator (npm package gltf-validator, installed by
// `make deps` into tools/node_modules). Usage: node tools/gltf_validate.mjs FILE...
// Prints one JSON object per file: {file, errors, warnings, infos, hints, messages: [first 20 issues]}.
// Exit status: 0 when no file has errors, 1 when some file has, 2 when the validator or a file is missing.
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { createRequire } from 'node:module';

const require = createRequire(import.meta.url);
let validator;
try {
  validator = require('gltf-validator');
} catch (e) {
  console.error('gltf_validate: gltf-validator is not installed (run `make deps`): ' + e.message);
  process.exit(2);
}

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error('usage: node tools/gltf_validate.mjs FILE...');
  process.exit(2);
}

let failed = false;
for (const file of files) {
  let bytes;
  try {
    bytes = new Uint8Array(await readFile(file));
  } catch (e) {
    console.error(`gltf_validate: ${file}: ${e.message}`);
    process.exit(2);
  }
  const report = await validator.validateBytes(bytes, {
    uri: file,
    maxIssues: 1000,
    externalResourceFunction: (uri) =>
      readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
  });
  const issues = report.issues;
  const severities = ['error', 'warning', 'info', 'hint'];
  const messages = issues.messages.slice(0, 20).map(
    (m) => `${severities[m.severity] ?? m.severity} ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  console.log(JSON.stringify({
    file,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    hints: issues.numHints,
    messages,
  }));
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
