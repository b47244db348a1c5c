// Runs the Khronos glTF Validator (npm gltf-validator) on the .glb files named on the command
// line and prints one JSON line per file: {file, errors, warnings, infos, hints, messages}.
// Exits 1 when any file has an error or a warning. Used by tests/export/test_gltf_valid.py.
import { readFile } from "node:fs/promises";
import validator from "gltf-validator";

let bad = false;
for (const file of process.argv.slice(2)) {
  const data = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(data, { uri: file, maxIssues: 100 });
  const i = report.issues;
  bad ||= i.numErrors > 0 || i.numWarnings > 0;
  console.log(JSON.stringify({ file, errors: i.numErrors, warnings: i.numWarnings, infos: i.numInfos,
    hints: i.numHints, messages: i.messages.map((m) => `${m.severity} ${m.code} ${m.pointer ?? ""}: ${m.message}`),
    info: report.info }));
}
process.exit(bad ? 1 : 0);
