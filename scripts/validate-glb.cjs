#!/usr/bin/env node
// Runs the Khronos glTF-Validator (npm gltf-validator, installed in web/node_modules by
// scripts/install-deps.sh) on GLB files and prints each one's counts and messages.
// Usage: node scripts/validate-glb.cjs FILE.glb... [--json REPORT.json]
// Exit status: 0 when every file has 0 errors and 0 warnings, 1 otherwise, 2 on a usage error.
'use strict';
const fs = require('fs');
const path = require('path');

const web = process.env.GLINT_WEB_DIR || path.join(__dirname, '..', 'web');
let validator;
try {
  validator = require(path.join(web, 'node_modules', 'gltf-validator'));
} catch (error) {
  console.error(`validate-glb: gltf-validator not found under ${web}/node_modules ` +
                '(run scripts/install-deps.sh)');
  process.exit(2);
}

async function main(argv) {
  const files = [];
  let jsonOut = null;
  for (let i = 0; i < argv.length; ++i) {
    if (argv[i] === '--json') jsonOut = argv[++i];
    else files.push(argv[i]);
  }
  if (files.length === 0) {
    console.error('usage: node scripts/validate-glb.cjs FILE.glb... [--json REPORT.json]');
    return 2;
  }
  let clean = true;
  const reports = {};
  for (const file of files) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: path.basename(file),
      maxIssues: 100,
      writeTimestamp: false,
    });
    const issues = report.issues;
    reports[file] = report;
    console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
                `${issues.numInfos} infos, ${issues.numHints} hints`);
    for (const message of issues.messages)
      console.log(`  [${['error', 'warning', 'info', 'hint'][message.severity]}] ` +
                  `${message.code} ${message.pointer || ''}: ${message.message}`);
    if (issues.numErrors > 0 || issues.numWarnings > 0) clean = false;
  }
  if (jsonOut) fs.writeFileSync(jsonOut, JSON.stringify(reports, null, 1));
  return clean ? 0 : 1;
}

main(process.argv.slice(2)).then((code) => process.exit(code), (error) => {
  console.error(`validate-glb: ${error.message || error}`);
  process.exit(2);
});
