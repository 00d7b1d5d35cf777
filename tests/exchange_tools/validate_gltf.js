// Runs the Khronos glTF-Validator on each file named on the command line and
// prints one JSON report per file (one line each): the test suite reads them.
// Usage: node validate_gltf.js <validator module folder> FILE...
const fs = require('fs');
const path = require('path');
const validator = require(path.resolve(process.argv[2]));

async function main() {
  for (const file of process.argv.slice(3)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: path.basename(file),
      maxIssues: 0,
      externalResourceFunction: (uri) => Promise.reject(new Error('external resources are not expected: ' + uri)),
    });
    console.log(JSON.stringify({file: file, issues: report.issues}));
  }
}

main().catch((err) => { console.error(String(err)); process.exit(2); });
