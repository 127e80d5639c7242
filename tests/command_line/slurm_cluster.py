"""A one-node Slurm cluster on localhost for the tests: Debian's ``slurmctld`` and ``slurmd`` with a ``munged`` of its
own, every file (key, sockets, state, spool, logs) in one folder, free ports, no cgroups; started by `start`, stopped
by `Cluster.stop` with nothing left running. Needs root (slurmd runs jobs as their user) and the slurm-wlm packages
(`tools/setup.sh` installs them as root on Debian)."""

import os
import shutil
import signal
import socket
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

DAEMONS = ("slurmctld", "slurmd", "munged", "sbatch", "squeue", "sinfo", "scontrol")


def missing():
    """Why a local cluster cannot run here ("" when it can)."""
    if os.geteuid() != 0:
        return "a local Slurm cluster needs root (slurmd runs each job as its user)"
    absent = [d for d in DAEMONS if shutil.which(d) is None]
    return f"Slurm is not installed ({', '.join(absent)} missing; tools/setup.sh installs it as root)" if absent else ""


def _free_ports(n):
    socks = [socket.socket() for _ in range(n)]
    try:
        for s in socks:
            s.bind(("127.0.0.1", 0))
        return [s.getsockname()[1] for s in socks]
    finally:
        for s in socks:
            s.close()


@dataclass
class Cluster:
    folder: Path
    env: dict
    procs: list = field(default_factory=list)

    def run(self, *args, env=None, **kw):
        """``ARGS`` in a process with the cluster's SLURM_CONF (``env``: another environment): CompletedProcess."""
        return subprocess.run([str(a) for a in args], env=env or self.env, capture_output=True, text=True, timeout=120,
                              **kw)

    def wait_idle(self, timeout=600):
        """Wait until no job is queued or running; returns each job's state (``scontrol show job``)."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if not self.run("squeue", "-h").stdout.strip():
                break
            time.sleep(1)
        else:
            raise TimeoutError(f"Slurm jobs still queued after {timeout} s:\n{self.run('squeue').stdout}")
        shown = self.run("scontrol", "-o", "show", "job").stdout
        return [line.split("JobState=")[1].split()[0] for line in shown.splitlines() if "JobState=" in line]

    def running(self, timeout=120):
        """The id of the first job step seen running (an array task: ``JOB_TASK``)."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            ids = self.run("squeue", "-h", "-t", "R", "-o", "%i").stdout.split()
            if ids:
                return ids[0]
            time.sleep(0.1)
        raise TimeoutError(f"no Slurm job ran within {timeout} s:\n{self.run('squeue').stdout}")

    def release(self, job, timeout=60):
        """Let requeued ``job`` start again at once: Slurm holds a requeued job back by its begin time (two minutes),
        which can only be moved once the job is pending again (after it stopped: COMPLETING)."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            state = self.run("squeue", "-h", "-j", job, "-o", "%T").stdout.strip()
            if state in ("", "RUNNING", "COMPLETED"):
                return
            if state == "PENDING":
                self.run("scontrol", "update", f"JobId={job}", "StartTime=now")
            time.sleep(0.2)
        raise TimeoutError(f"requeued Slurm job {job} did not start again within {timeout} s")

    def restarts(self):
        """Each job's restart count (``scontrol show job``): {job id: count}."""
        shown = self.run("scontrol", "-o", "show", "job").stdout
        out = {}
        for line in shown.splitlines():
            fields = dict(f.split("=", 1) for f in line.split() if "=" in f)
            if "JobId" in fields:
                name = fields["JobId"] if fields.get("ArrayTaskId") in (None, "N/A") else \
                    f"{fields.get('ArrayJobId')}_{fields['ArrayTaskId']}"
                out[name] = int(fields.get("Restarts", 0))
        return out

    def stop(self):
        """Stop the daemons (slurmd, slurmctld, munged) and wait for them: nothing left running."""
        for pidfile in ("slurmd.pid", "slurmctld.pid", "munged.pid"):
            path = self.folder / pidfile
            if path.exists():
                try:
                    os.kill(int(path.read_text().split()[0]), signal.SIGTERM)
                except (ProcessLookupError, ValueError):
                    pass
        for proc in self.procs:
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        end = time.monotonic() + 30
        while self.left() and time.monotonic() < end:
            time.sleep(0.2)

    def left(self):
        """The cluster's processes still running (pids), found by their config or socket path on the command line."""
        out = []
        for entry in Path("/proc").iterdir():
            if entry.name.isdigit():
                try:
                    cmd = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
                except OSError:
                    continue
                if str(self.folder) in cmd:
                    out.append(int(entry.name))
        return out


def start(folder, cpus=2):
    """Start a one-node cluster whose files live in ``folder`` (made): a `Cluster`; its ``env`` has SLURM_CONF."""
    folder = Path(folder)
    for sub in ("state", "spool"):
        (folder / sub).mkdir(parents=True, exist_ok=True)
    folder.chmod(0o700)
    key = folder / "munge.key"
    key.write_bytes(os.urandom(1024))
    key.chmod(0o400)
    sock = folder / "munge.socket"
    subprocess.run(["munged", "--force", f"--key-file={key}", f"--socket={sock}", f"--pid-file={folder}/munged.pid",
                    f"--log-file={folder}/munged.log", f"--seed-file={folder}/munged.seed"], check=True, timeout=30)
    ctld_port, d_port = _free_ports(2)
    conf = folder / "slurm.conf"
    conf.write_text(f"""ClusterName=tessera
SlurmctldHost=localhost(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort={ctld_port}
SlurmdPort={d_port}
AuthType=auth/munge
AuthInfo=socket={sock}
CredType=cred/munge
StateSaveLocation={folder}/state
SlurmdSpoolDir={folder}/spool
SlurmctldPidFile={folder}/slurmctld.pid
SlurmdPidFile={folder}/slurmd.pid
SlurmctldLogFile={folder}/slurmctld.log
SlurmdLogFile={folder}/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
NodeName=localhost NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN
PartitionName=main Nodes=localhost Default=YES MaxTime=INFINITE State=UP
""")
    env = dict(os.environ, SLURM_CONF=str(conf))
    cluster = Cluster(folder, env)
    try:
        for cmd in (["slurmctld", "-D", "-f", conf], ["slurmd", "-D", "-N", "localhost", "-f", conf]):
            cluster.procs.append(subprocess.Popen([str(c) for c in cmd], env=env, stdout=subprocess.DEVNULL,
                                                  stderr=subprocess.DEVNULL))
        end = time.monotonic() + 60
        while time.monotonic() < end:
            if cluster.run("sinfo", "-h", "-o", "%t").stdout.strip() == "idle":
                return cluster
            time.sleep(0.5)
        logs = "".join((folder / n).read_text(errors="replace")[-1500:] for n in ("slurmctld.log", "slurmd.log")
                       if (folder / n).exists())
        raise RuntimeError(f"the local Slurm node did not come up:\n{logs}")
    except BaseException:
        cluster.stop()
        raise
