"""A `plan` written in a scheduler's own format: Open Job Description, Slurm, Flamenco (JSON is the plan itself).

- ``openjd``: an Open Job Description job template (``jobtemplate-2023-09``, what AWS Deadline Cloud runs and
  ``openjd run`` runs locally): one step per plan step, its task parameters the plan's (frames as INT, blocks and
  objects as STRING, associated so each task gets its own combination), its command the step's argv; a job
  parameter ``Blender`` names the executable (default ``blender``).
- ``slurm``: a bash script that, run where ``sbatch`` is, submits one array job per step, each after the steps it
  needs (``--dependency=afterok``); each array task runs its task's command line. ``TESSERA_BLENDER`` names the
  executable, ``TESSERA_SBATCH`` adds sbatch options (a partition, an account).
- ``flamenco``: a Flamenco 3 job type (JavaScript, for the Manager's ``scripts/`` folder) whose ``plan`` setting holds
  this plan: each task a Flamenco task running ``{blender}``, the plan's order kept as dependencies.

Every format carries the same command lines as the JSON plan, so a task means the same whichever scheduler runs it.
"""

import json
import shlex

FORMATS = ("json", "openjd", "slurm", "flamenco")
OPENJD_VERSION = "jobtemplate-2023-09"
#: Task parameters that are whole numbers (OpenJD INT); the others are STRING.
_INT_PARAMS = ("Frame",)


def render(fmt, plan):
    """The text of ``plan`` (`plan.plan_dict`) in format ``fmt`` (one of `FORMATS`)."""
    if fmt == "json":
        return json.dumps(plan, indent=1)
    if fmt == "openjd":
        return json.dumps(openjd_template(plan), indent=1)
    if fmt == "slurm":
        return slurm_script(plan)
    if fmt == "flamenco":
        return flamenco_job_type(plan)
    raise ValueError(f"unknown plan format {fmt!r}; choose one of {', '.join(FORMATS)}")


def _values(plan, step, name, where=None):
    """The values of task parameter ``name`` over ``step``'s tasks (those whose params include ``where``), in task
    order."""
    return [task["params"][name] for task in plan["tasks"] if task["step"] == step["name"]
            and all(task["params"].get(k) == v for k, v in (where or {}).items())]


def _definition(name, values):
    if name in _INT_PARAMS:
        return {"name": name, "type": "INT", "range": [int(v) for v in values]}
    return {"name": name, "type": "STRING", "range": [str(v) for v in values]}


def openjd_template(plan):
    """The Open Job Description job template of ``plan``: a dict (JSON). A step's frames multiply its other
    parameters (every block of every frame); the others go together, element by element (a block and its part)."""
    steps = []
    for step in plan["steps"]:
        entry = {"name": step["name"],
                 "script": {"actions": {"onRun": {"command": "{{Param.Blender}}",
                                                  "args": ["-c", "tessera", *step["argv"]]}}}}
        names = list(step["params"])
        if names:
            frames = []
            if "Frame" in names:
                frames = list(dict.fromkeys(_values(plan, step, "Frame")))
                names.remove("Frame")
            where = {"Frame": frames[0]} if frames else None
            definitions = [_definition("Frame", frames)] if frames else []
            definitions += [_definition(name, _values(plan, step, name, where)) for name in names]
            entry["parameterSpace"] = {"taskParameterDefinitions": definitions}
            rest = "(" + ", ".join(names) + ")" if len(names) > 1 else "".join(names)
            combination = " * ".join(part for part in ("Frame" if frames else "", rest) if part)
            if len(definitions) > 1:
                entry["parameterSpace"]["combination"] = combination
        if step["after"]:
            entry["dependencies"] = [{"dependsOn": name} for name in step["after"]]
        steps.append(entry)
    return {"specificationVersion": OPENJD_VERSION, "name": f"Tessera {plan['verb']}",
            "parameterDefinitions": [{"name": "Blender", "type": "STRING", "default": "blender",
                                      "description": "The Blender executable on the workers (Tessera installed)"}],
            "steps": steps}


def slurm_script(plan):
    """A bash script that submits ``plan`` to Slurm: one array job per step, each after the steps it needs."""
    lines = ["#!/bin/bash",
             f"# Tessera plan: {plan['verb']}, {len(plan['tasks'])} tasks in {len(plan['steps'])} steps.",
             "# Run it where sbatch is: it submits one array job per step, each after the steps it needs.",
             "# TESSERA_BLENDER: the Blender on the nodes (default: blender); TESSERA_SBATCH: more sbatch options.",
             "set -euo pipefail",
             'blender=${TESSERA_BLENDER:-blender}',
             'if [ "${1:-}" = "--task" ]; then',
             '  case "$2:${SLURM_ARRAY_TASK_ID:?run by sbatch --array}" in']
    index = {}
    for task in plan["tasks"]:
        step = task["step"]
        i = index.setdefault(step, [])
        words = " ".join(shlex.quote(w) for w in ["-c", "tessera", *task["argv"]])
        lines.append(f"    {shlex.quote(step)}:{len(i)}) exec \"$blender\" {words} ;;")
        i.append(task)
    lines += ['    *) echo "tessera plan: no task $2:$SLURM_ARRAY_TASK_ID" >&2; exit 2 ;;', "  esac", "fi",
              'script=$(readlink -f "$0")',
              'read -r -a extra <<< "${TESSERA_SBATCH:-}"',
              'submit() { sbatch --parsable "${extra[@]}" "$@"; }']
    for n, step in enumerate(plan["steps"]):
        count = len(index.get(step["name"], []))
        if not count:
            continue
        after = ":".join(f"${{job_{plan['steps'].index(s)}}}" for s in plan["steps"] if s["name"] in step["after"])
        dep = f" --dependency=afterok:{after}" if after else ""
        name = shlex.quote(f"tessera-{plan['verb']}-{step['name'].lower()}")
        lines.append(f"job_{n}=$(submit --job-name={name} --array=0-{count - 1}{dep} "
                     f"\"$script\" --task {shlex.quote(step['name'])})")
        lines.append(f"job_{n}=${{job_{n}%%;*}}")
        lines.append(f'echo "{step["name"]}: job $job_{n} ({count} tasks)"')
    return "\n".join(lines) + "\n"


_FLAMENCO = """// Tessera plan as a Flamenco 3 job type: save as scripts/tessera-plan.js beside the Flamenco Manager,
// then submit a job of type "tessera-plan" (its "plan" setting defaults to the plan this file was written from).
const JOB_TYPE = {
  label: "Tessera Plan",
  settings: [
    { key: "plan", type: "string", required: true, default: PLAN_JSON,
      description: "The JSON printed by 'blender -c tessera plan'" },
  ],
};

function compileJob(job) {
  const plan = JSON.parse(job.settings.plan);
  const made = {};
  for (const t of plan.tasks) {
    const task = author.Task(t.name, "blender");
    task.addCommand(author.Command("exec", { exe: "{blender}", args: ["-c", "tessera"].concat(t.argv) }));
    for (const name of t.after) task.addDependency(made[name]);
    job.addTask(task);
    made[t.name] = task;
  }
}
"""


def flamenco_job_type(plan):
    """The Flamenco 3 job type script running ``plan``: JavaScript text."""
    return _FLAMENCO.replace("PLAN_JSON", json.dumps(json.dumps(plan)))

