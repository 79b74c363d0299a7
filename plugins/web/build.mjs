// Builds the page's scripts into dist/: atlas_view.js (the viewer and
// three.js, @takram/three-clouds and its peers, bundled by esbuild) and
// atmosphere.js (@takram/three-atmosphere's precomputed tables as data URLs,
// so that a page opened from disk needs no server). Run by scripts/web.sh.
import { build } from 'esbuild'
import { mkdirSync, readFileSync, writeFileSync, copyFileSync } from 'node:fs'
import { dirname, join } from 'node:path'
import { fileURLToPath } from 'node:url'

const here = dirname(fileURLToPath(import.meta.url))
const dist = join(here, 'dist')
mkdirSync(dist, { recursive: true })
await build({
  entryPoints: [join(here, 'src/main.js')],
  bundle: true,
  format: 'iife',
  minify: true,
  legalComments: 'external',
  outfile: join(dist, 'atlas_view.js'),
  logLevel: 'warning'
})
const assets = join(here, 'node_modules/@takram/three-atmosphere/assets')
const tables = {}
for (const name of ['transmittance.bin', 'scattering.bin', 'irradiance.bin', 'higher_order_scattering.bin']) {
  tables[name] = 'data:application/octet-stream;base64,' + readFileSync(join(assets, name)).toString('base64')
}
writeFileSync(join(dist, 'atmosphere.js'), `window.ATLAS_ATMOSPHERE = ${JSON.stringify(tables)};\n`)
copyFileSync(join(here, 'index.html'), join(dist, 'index.html'))
console.log(`built ${dist}`)
