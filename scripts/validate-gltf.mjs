// Validates glTF files (paths as given) with the Khronos glTF validator (npm: gltf-validator),
// their external resources read from beside them, and prints one JSON line per
// file: its name, its SHA-256 and those of the files it references, the validator's version and its counts of errors,
// warnings, infos and hints, and the messages of the errors and warnings.
// Exits 1 when a file has an error. Used by scripts/make-gltf-assets.sh.
import crypto from 'crypto';
import fs from 'fs';
import path from 'path';
// GLTF_VALIDATOR: the package's folder, when it is not installed beside this script.
const validator = (await import(process.env.GLTF_VALIDATOR ? `${process.env.GLTF_VALIDATOR}/index.js` : 'gltf-validator')).default;

const sha256 = (data) => crypto.createHash('sha256').update(data).digest('hex');
let failed = false;
for (const file of process.argv.slice(2)) {
  const bytes = fs.readFileSync(file);
  const folder = path.dirname(file);
  const resources = {};
  const report = await validator.validateBytes(new Uint8Array(bytes), {
    uri: path.basename(file),
    externalResourceFunction: (uri) =>
      fs.promises.readFile(path.join(folder, decodeURIComponent(uri))).then((data) => {
        resources[uri] = sha256(data);
        return new Uint8Array(data);
      }),
  });
  const issues = report.issues;
  const serious = issues.messages.filter((m) => m.severity <= 1).map((m) => `${m.code} at ${m.pointer}: ${m.message}`);
  console.log(JSON.stringify({
    file,
    sha256: sha256(bytes),
    resources,
    validator: report.validatorVersion,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    hints: issues.numHints,
    messages: serious,
  }));
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
