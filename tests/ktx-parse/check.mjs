// Reads each KTX2 file named on the command line with ktx-parse (the parser three.js's
// KTX2Loader uses) and prints one JSON line per file: what the parser found, for the Rust
// end-to-end tests to check. Exits 1 (with the file and the parser's message on stderr) when the
// parser refuses a file.
import { readFileSync } from 'node:fs';
import { read } from 'ktx-parse';

let failed = false;
for (const path of process.argv.slice(2)) {
    try {
        const container = read(new Uint8Array(readFileSync(path)));
        const dfd = container.dataFormatDescriptor[0];
        console.log(JSON.stringify({
            path,
            vkFormat: container.vkFormat,
            typeSize: container.typeSize,
            pixelWidth: container.pixelWidth,
            pixelHeight: container.pixelHeight,
            pixelDepth: container.pixelDepth,
            layerCount: container.layerCount,
            faceCount: container.faceCount,
            levelCount: container.levelCount,
            supercompressionScheme: container.supercompressionScheme,
            levelBytes: container.levels.map((level) => level.levelData.byteLength),
            keys: Object.keys(container.keyValue).sort(),
            colorModel: dfd.colorModel,
            colorPrimaries: dfd.colorPrimaries,
            transferFunction: dfd.transferFunction,
            bytesPlane0: dfd.bytesPlane[0],
            samples: dfd.samples.map((s) => [s.bitOffset, s.bitLength, s.channelType]),
        }));
    } catch (error) {
        console.error(`error: ${path}: ktx-parse refused it: ${error.message}`);
        failed = true;
    }
}
process.exit(failed ? 1 : 0);
