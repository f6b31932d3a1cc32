// Reads IES LM-63 files with three.js's IESLoader (npm package `three`,
// examples/jsm/loaders/IESLoader.js), a reader lumislab did not write, and prints what it parsed
// as one JSON line per file: the angle counts and angles, the candela values as the loader keeps
// them (multiplied by the file's multiplier and factors, then divided by their maximum), and the
// texture its public parse() builds from them. tests/export/independent_readers_test.cc compares
// that with lumislab's own reader.
//
// Usage: node ies_three.mjs <folder holding node_modules/three> <file.ies>...
//
// The loader keeps its parsed lamp (IESLamp) private; this script loads the module's source with
// one line added that exports it, and the import of 'three' pointed at the package's build.
import { readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [root, ...files] = process.argv.slice(2);
const three = join(resolve(root), 'node_modules', 'three');
const threeUrl = pathToFileURL(join(three, 'build', 'three.module.js')).href;
let source = readFileSync(join(three, 'examples', 'jsm', 'loaders', 'IESLoader.js'), 'utf8');
source = source.replace(/from\s+'three'/g, `from '${threeUrl}'`) + '\nexport { IESLamp };\n';
const { IESLoader, IESLamp } =
    await import('data:text/javascript,' + encodeURIComponent(source));
const { FloatType } = await import(threeUrl);

for (const file of files) {
  const text = readFileSync(file, 'utf8');
  const lamp = new IESLamp(text);
  const loader = new IESLoader();
  loader.type = FloatType;
  const texture = loader.parse(text);
  const data = Array.from(texture.image.data);
  console.log(JSON.stringify({
    file,
    lumens: lamp.lumens,
    multiplier: lamp.multiplier,
    numVerAngles: lamp.numVerAngles,
    numHorAngles: lamp.numHorAngles,
    verAngles: lamp.verAngles,
    horAngles: lamp.horAngles,
    candela: lamp.candelaValues,
    texture: {
      width: texture.image.width,
      height: texture.image.height,
      finite: data.every(Number.isFinite),
      max: Math.max(...data),
    },
  }));
}
