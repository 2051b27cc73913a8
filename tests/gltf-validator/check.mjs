// Validates each glTF file named on the command line with the Khronos glTF validator (its npm
// build), loading the buffers it names from beside it, and prints one JSON line per file: the
// validator's counts of errors, warnings, infos and hints, its messages, and the extensions it
// found, for the Rust end-to-end tests to check. Exits 1 when the validator cannot run on a file.
import { readFileSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import validator from 'gltf-validator';

let failed = false;
for (const file of process.argv.slice(2)) {
    try {
        const report = await validator.validateBytes(new Uint8Array(readFileSync(file)), {
            uri: path.basename(file),
            externalResourceFunction: (uri) =>
                readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
        });
        console.log(JSON.stringify({
            path: file,
            validatorVersion: report.validatorVersion,
            errors: report.issues.numErrors,
            warnings: report.issues.numWarnings,
            infos: report.issues.numInfos,
            hints: report.issues.numHints,
            messages: report.issues.messages.map((m) => `${m.code} ${m.pointer ?? ''}: ${m.message}`),
            extensionsUsed: report.info?.extensionsUsed ?? [],
            resources: (report.info?.resources ?? []).map((r) => r.uri ?? r.pointer),
        }));
    } catch (error) {
        console.error(`error: ${file}: the glTF validator could not run: ${error}`);
        failed = true;
    }
}
process.exit(failed ? 1 : 0);
