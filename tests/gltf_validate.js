// The Khronos glTF validator (npm gltf-validator) on one file: prints its report's issues as
// JSON. Usage: node gltf_validate.js MODULE_DIR FILE  (MODULE_DIR: where npm installed it).
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require(path.resolve(process.argv[2], 'node_modules', 'gltf-validator'));
validator.validateBytes(new Uint8Array(fs.readFileSync(process.argv[3])))
  .then((report) => { process.stdout.write(JSON.stringify(report.issues)); })
  .catch((err) => { process.stderr.write(String(err)); process.exit(1); });
