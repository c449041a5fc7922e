// Validates rendered Kubernetes manifests (multi-document YAML on stdin or
// in the files given) against the Kubernetes OpenAPI schemas, using the
// JSON-schema validators that kubernetes-models generates from them
// (ServiceMonitor: @kubernetes-models/prometheus-operator, from the
// operator's CRD schema). Exits 1 naming every invalid object.
//
//   kubectl kustomize deploy/kubernetes/overlays/production | node validate.mjs
import fs from "node:fs";
import yaml from "js-yaml";

// apiVersion -> the module holding its models.
function moduleFor(apiVersion) {
  if (apiVersion.startsWith("monitoring.coreos.com/")) {
    return `@kubernetes-models/prometheus-operator/${apiVersion}`;
  }
  return `kubernetes-models/${apiVersion}`;
}

async function validate(doc, where) {
  const { apiVersion, kind } = doc;
  if (!apiVersion || !kind) return [`${where}: no apiVersion or kind`];
  let mod;
  try {
    mod = await import(moduleFor(apiVersion));
  } catch (e) {
    return [`${where}: unknown apiVersion ${apiVersion} (${e.code || e.message})`];
  }
  const Model = mod[kind];
  if (typeof Model !== "function") return [`${where}: unknown kind ${kind} in ${apiVersion}`];
  try {
    new Model(doc).validate();
  } catch (e) {
    const details = (e.errors || []).map((x) => `${x.instancePath || "/"} ${x.message}`).join("; ");
    return [`${where}: ${kind} ${doc.metadata?.name}: ${details || e.message}`];
  }
  return [];
}

const inputs = process.argv.length > 2
  ? process.argv.slice(2).map((f) => [f, fs.readFileSync(f, "utf8")])
  : [["<stdin>", fs.readFileSync(0, "utf8")]];
const problems = [];
let count = 0;
for (const [name, text] of inputs) {
  const docs = yaml.loadAll(text).filter((d) => d != null);
  for (const [i, doc] of docs.entries()) {
    count++;
    problems.push(...(await validate(doc, `${name}[${i}]`)));
  }
}
for (const p of problems) console.log(`invalid: ${p}`);
if (count === 0) problems.push("no objects");
console.log(`${count} objects, ${problems.length} invalid`);
process.exit(problems.length ? 1 : 0);
