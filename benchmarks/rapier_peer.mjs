// Rapier 2D's FEM soft body as a peer of deforma: a column hanging from its pinned top.
//
// Usage: node rapier_peer.mjs INPUT.json      (or "-" to read the JSON from standard input)
//
// INPUT holds the mesh and the case, all in SI units (the world is 2D: a slab of unit
// thickness, so rho is kg/m^2 and E is N/m, as in deforma):
//   vertices   [[x, y], ...]          rest positions (m)
//   triangles  [[i, j, k], ...]       counter-clockwise (clockwise ones are turned round)
//   pinned     [i, ...]               vertices held in place (the top row)
//   tip        [i, ...]               vertices whose mean downward displacement is reported
//   E, nu, rho                        Young's modulus, Poisson's ratio, density
//   model      "corotated" | "neo-hookean"                     (default "corotated")
//   gravity    9.81 (m/s^2, pointing down)      dt   1/60 (s)
//   settle_steps   steps before the timed ones  (default 180: 3 s at 1/60 s)
//   timed_steps    steps each timed on its own  (default 60)
//   linear_damping  Rapier's linear damping of the particles, 1/s (default 0): v / (1 + dt c)
//                   each step, the same law as deforma's air_drag
//   solver_iterations  Rapier's substeps (numSolverIterations; default: Rapier's, 4)
//   fem_max_linear_iterations, fem_linear_tolerance, fem_max_dense_dofs
//              the FEM solver's linear solves (defaults: Rapier's, 20, 1e-5 and 600; its docs say a
//              body of more degrees of freedom than the last is solved by conjugate gradients, but
//              the iteration cap also changed the settled column at 410 degrees of freedom)
//   modules    a node_modules folder holding @dimforge/rapier2d-compat (optional)
//   positions  true to add the final particle positions ([[x, y], ...]) to the output
//   times      true to add every timed step's wall time (step_s, in seconds) to the output
//
// The package is looked for in INPUT's "modules", then $DEFORMA_RAPIER_MODULES, then the
// node_modules folder beside this script; each may be a node_modules folder or a folder that
// holds one. Nothing is downloaded. Prints one JSON object on standard output:
//   package, version, particles, cells, mass (kg), steps, simulated_s,
//   tip_displacement (m, downward, after all the steps), max_speed (m/s at the end),
//   median_step_s and mean_step_s (over the timed steps), settings (what was used),
//   and positions and step_s when asked.
// Exits with a one-line message on standard error: 1 for bad input, 2 when the package is
// missing, 3 when it has no FEM soft bodies (before 0.21.0), 4 when Rapier did not take the mesh.

import { createRequire } from "node:module";
import { existsSync, readFileSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const PACKAGE = "@dimforge/rapier2d-compat";
const HERE = dirname(fileURLToPath(import.meta.url));

function fail(code, message) {
  process.stderr.write(message + "\n");
  process.exit(code);
}

function findPackage(candidates) {
  for (const c of candidates) {
    if (!c) continue;
    for (const dir of [resolve(c), resolve(c, "node_modules")]) {
      if (existsSync(join(dir, PACKAGE, "package.json"))) return dir;
    }
  }
  return null;
}

const arg = process.argv[2];
if (!arg) fail(1, "usage: node rapier_peer.mjs INPUT.json (or - for standard input)");
const input = JSON.parse(readFileSync(arg === "-" ? 0 : arg, "utf8"));

const modules = findPackage([input.modules, process.env.DEFORMA_RAPIER_MODULES, join(HERE, "node_modules")]);
if (!modules) {
  fail(2, `${PACKAGE} not found (looked in the input's "modules", $DEFORMA_RAPIER_MODULES and ` +
    `${join(HERE, "node_modules")}); install it with: npm install --no-save --no-package-lock ` +
    `--prefix DIR ${PACKAGE}@0.21.0, DIR being ${HERE} or one named by DEFORMA_RAPIER_MODULES`);
}
const require = createRequire(join(modules, "__deforma__.js"));
const RAPIER = require(PACKAGE);
const version = JSON.parse(readFileSync(join(modules, PACKAGE, "package.json"), "utf8")).version;
await RAPIER.init();
if (!RAPIER.SoftBodyDesc || !RAPIER.SoftBodySolver || RAPIER.SoftBodySolver.Fem === undefined) {
  fail(3, `${PACKAGE} ${version} has no FEM soft bodies (SoftBodySolver.Fem); 0.21.0 or newer is needed`);
}

const E = Number(input.E), nu = Number(input.nu), rho = Number(input.rho);
const gravity = input.gravity ?? 9.81;
const dt = input.dt ?? 1 / 60;
const settleSteps = input.settle_steps ?? 180;
const timedSteps = input.timed_steps ?? 60;
const model = input.model ?? "corotated";
const cellModel = { "corotated": RAPIER.SoftBodyCellModel.Corotational,
                    "neo-hookean": RAPIER.SoftBodyCellModel.NeoHookean }[model];
if (cellModel === undefined) fail(1, `model must be "corotated" or "neo-hookean", not ${JSON.stringify(model)}`);
if (!(E > 0) || !(rho > 0) || !(nu > -1 && nu < 0.5)) fail(1, "E and rho must be > 0 and nu in (-1, 0.5)");

// The mesh, with each triangle's mass lumped a third to each corner (as deforma does).
const verts = input.vertices, n = verts.length;
const positions = new Float32Array(2 * n);
verts.forEach(([x, y], i) => { positions[2 * i] = x; positions[2 * i + 1] = y; });
const cells = new Uint32Array(3 * input.triangles.length);
const masses = new Float64Array(n);
let turned = 0;
input.triangles.forEach(([a, b, c], t) => {
  const [ax, ay] = verts[a], [bx, by] = verts[b], [cx, cy] = verts[c];
  const twice = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay);
  if (twice < 0) { [b, c] = [c, b]; turned++; }
  cells.set([a, b, c], 3 * t);
  for (const v of [a, b, c]) masses[v] += rho * Math.abs(twice) / 6;
});

const world = new RAPIER.World({ x: 0, y: -gravity });
world.timestep = dt;
if (input.solver_iterations != null) world.numSolverIterations = input.solver_iterations;
const params = world.integrationParameters;
if (input.fem_max_linear_iterations != null) params.softBodiesFemMaxLinearIterations = input.fem_max_linear_iterations;
if (input.fem_linear_tolerance != null) params.softBodiesFemLinearTolerance = input.fem_linear_tolerance;
if (input.fem_max_dense_dofs != null) params.softBodiesFemMaxDenseDofs = input.fem_max_dense_dofs;
const material = new RAPIER.SoftBodyMaterial();
material.youngModulus = E;
material.poissonRatio = nu;
const desc = new RAPIER.SoftBodyDesc(positions)
  .setCells(cells)
  .setSolver(RAPIER.SoftBodySolver.Fem)
  .setCellModel(cellModel)
  .setMaterial(material)
  .setMasses(masses)
  .setPinnedParticles(Uint32Array.from(input.pinned))
  .setLinearDamping(input.linear_damping ?? 0)
  .setNoSurfaceCollider()   // the column touches nothing; deforma's has no collider either
  .setCanSleep(false);      // a body asleep would make the timed steps free
const body = world.createSoftBody(desc);
// Rapier ignores a mass array of the wrong length without a word: check what it took.
const mass = body.mass(), expected = masses.reduce((s, m) => s + m, 0);
if (body.numParticles() !== n || Math.abs(mass - expected) > 1e-4 * expected) {
  fail(4, `Rapier built ${body.numParticles()} particles of ${mass} kg, not ${n} of ${expected} kg`);
}

const tip = Uint32Array.from(input.tip);
const rest = tip.reduce((s, i) => s + verts[i][1], 0) / tip.length;
function tipDisplacement() {
  const p = body.particlePositions();
  return rest - tip.reduce((s, i) => s + p[2 * i + 1], 0) / tip.length;
}

for (let k = 0; k < settleSteps; k++) world.step();
const times = new Float64Array(timedSteps);
for (let k = 0; k < timedSteps; k++) {
  const t0 = process.hrtime.bigint();
  world.step();
  times[k] = Number(process.hrtime.bigint() - t0) * 1e-9;
}
const sorted = Array.from(times).sort((a, b) => a - b);
const median = sorted.length ? (sorted.length % 2 ? sorted[(sorted.length - 1) / 2]
  : 0.5 * (sorted[sorted.length / 2 - 1] + sorted[sorted.length / 2])) : null;
const v = body.particleVelocities();
let maxSpeed = 0;
for (let i = 0; i < n; i++) maxSpeed = Math.max(maxSpeed, Math.hypot(v[2 * i], v[2 * i + 1]));

const out = {
  package: PACKAGE, version, particles: n, cells: body.numCells(), mass,
  steps: settleSteps + timedSteps, simulated_s: (settleSteps + timedSteps) * dt,
  tip_displacement: tipDisplacement(), max_speed: maxSpeed,
  median_step_s: median, mean_step_s: timedSteps ? times.reduce((s, t) => s + t, 0) / timedSteps : null,
  settings: { solver: "Fem", model, E, nu, rho, gravity, dt, linear_damping: input.linear_damping ?? 0,
              solver_iterations: world.numSolverIterations, turned_triangles: turned,
              fem_linear_tolerance: params.softBodiesFemLinearTolerance,
              fem_max_linear_iterations: params.softBodiesFemMaxLinearIterations,
              fem_max_dense_dofs: params.softBodiesFemMaxDenseDofs },
};
if (input.times) out.step_s = Array.from(times);
if (input.positions) {
  const p = body.particlePositions();
  out.positions = Array.from({ length: n }, (_, i) => [p[2 * i], p[2 * i + 1]]);
}
process.stdout.write(JSON.stringify(out) + "\n");
