// Drafts the three FreeSewing designs used by emilion's garment tests and writes their SVGs
// next to this folder (scripts/patterns/{aaron,penelope,paco}.svg).
//
//   cd scripts/patterns/freesewing && npm ci && node generate.mjs
//
// One body for all three: the FreeSewing standard model `cisFemaleAdult34` from
// @freesewing/models. Default options, seam allowance 10 mm, except Paco's front pockets,
// which are turned off (they put a pocket flap into the outseams; the garment needs the
// body pieces only). See ../PROVENANCE.md.
import { writeFileSync } from 'node:fs'
import { fileURLToPath } from 'node:url'
import { dirname, join } from 'node:path'
import { Aaron } from '@freesewing/aaron'
import { Penelope } from '@freesewing/penelope'
import { Paco } from '@freesewing/paco'
import { cisFemaleAdult34 } from '@freesewing/models'

const MODEL = 'cisFemaleAdult34'
const SA_MM = 10
const out = join(dirname(fileURLToPath(import.meta.url)), '..')

const designs = [
  ['aaron', Aaron, {}],
  ['penelope', Penelope, {}],
  ['paco', Paco, { frontPockets: false }],
]

let failed = false
for (const [name, Design, options] of designs) {
  const pattern = new Design({ measurements: cisFemaleAdult34, sa: SA_MM, options })
  pattern.draft()
  const svg = pattern.render()
  const logs = pattern.setStores?.[0]?.logs ?? pattern.store.logs
  if (logs?.error?.length) {
    console.error(`${name}: drafting errors:`, logs.error)
    failed = true
    continue
  }
  const file = join(out, `${name}.svg`)
  writeFileSync(file, svg.endsWith('\n') ? svg : svg + '\n')
  console.log(`${name}: ${svg.length} bytes -> ${file}`)
}
console.log(`model ${MODEL}:`, JSON.stringify(cisFemaleAdult34))
process.exit(failed ? 1 : 0)
