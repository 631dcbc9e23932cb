"""A single-node Slurm cluster in a temporary directory, for tests: munged with its own key and
socket, slurmctld and slurmd (Debian's packages) on free ports, no cgroups, no accounting, the
node's CPUs and memory as this machine has them. `with SlurmCluster() as c:` gives an environment
(SLURM_CONF) in which sbatch, squeue and srun talk to it; the daemons are stopped on exit.
A daemon that does not start raises ClusterError with its log: a test fails with the reason instead
of being skipped."""
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time


class ClusterError(RuntimeError):
    pass


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


CONF = """ClusterName=angiotest
SlurmctldHost={host}(127.0.0.1)
SlurmUser={user}
SlurmdUser=root
SlurmctldPort={ctld_port}
SlurmdPort={d_port}
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket={d}/munge/munge.sock
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/slurmctld.pid
SlurmdPidFile={d}/slurmd.pid
SlurmctldLogFile={d}/slurmctld.log
SlurmdLogFile={d}/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
NodeName={host} NodeAddr=127.0.0.1 CPUs={cpus} RealMemory={mem} State=UNKNOWN
PartitionName=test Nodes={host} Default=YES MaxTime=INFINITE State=UP
"""


class SlurmCluster:
    def __init__(self):
        self.dir = None
        self.env = None

    def __enter__(self):
        missing = [
            x
            for x in ("munged", "mungekey", "slurmctld", "slurmd", "sbatch", "squeue", "srun")
            if shutil.which(x) is None and not os.path.exists(f"/usr/sbin/{x}")
        ]
        if missing:
            raise ClusterError(
                f"not installed: {', '.join(missing)} (scripts/setup.sh installs slurmctld, "
                "slurmd, slurm-client and munge)"
            )
        if os.geteuid() != 0:
            raise ClusterError("slurmd must run as root to start jobs (this test starts its own cluster)")
        self.dir = tempfile.mkdtemp(prefix="angio-slurm-")
        os.chmod(self.dir, 0o755)  # munged wants its socket's directories reachable
        d = self.dir
        for sub in ("munge", "state", "spool"):
            os.makedirs(os.path.join(d, sub), mode=0o700)
        os.chmod(os.path.join(d, "munge"), 0o755)
        host = socket.gethostname().split(".")[0]
        mem = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") // 2**20 // 2
        with open(os.path.join(d, "slurm.conf"), "w") as f:
            f.write(
                CONF.format(
                    host=host,
                    user="root",
                    ctld_port=free_port(),
                    d_port=free_port(),
                    d=d,
                    cpus=os.cpu_count() or 1,
                    mem=mem,
                )
            )
        self.env = dict(os.environ, SLURM_CONF=os.path.join(d, "slurm.conf"))
        sbin = lambda x: shutil.which(x) or f"/usr/sbin/{x}"  # noqa: E731
        m = os.path.join(d, "munge")
        self._run([sbin("mungekey"), "-c", "-k", f"{m}/munge.key"], "mungekey")
        self._run(
            [
                sbin("munged"),
                "-f",
                f"--socket={m}/munge.sock",
                f"--key-file={m}/munge.key",
                f"--log-file={m}/munged.log",
                f"--pid-file={m}/munged.pid",
                f"--seed-file={m}/munged.seed",
            ],
            "munged",
            log=f"{m}/munged.log",
        )
        self._run([sbin("slurmctld"), "-i"], "slurmctld", log=f"{d}/slurmctld.log")
        self._run([sbin("slurmd")], "slurmd", log=f"{d}/slurmd.log")
        deadline = time.time() + 60
        while time.time() < deadline:
            out = subprocess.run(["sinfo", "-h", "-o", "%t"], env=self.env, capture_output=True, text=True)
            if out.returncode == 0 and out.stdout.strip() in ("idle", "mix", "alloc"):
                return self
            time.sleep(0.5)
        self.__exit__(None, None, None)
        raise ClusterError(
            f"the node did not become idle in 60 s (sinfo: {out.stdout.strip()} "
            f"{out.stderr.strip()}); slurmctld.log:\n{self._tail(f'{d}/slurmctld.log')}\n"
            f"slurmd.log:\n{self._tail(f'{d}/slurmd.log')}"
        )

    def _run(self, cmd, name, log=None):
        out = subprocess.run(cmd, env=self.env, capture_output=True, text=True)
        if out.returncode != 0:
            self.__exit__(None, None, None)
            raise ClusterError(
                f"{name} did not start (exit {out.returncode}): {out.stderr.strip()}"
                + (f"\n{self._tail(log)}" if log else "")
            )

    @staticmethod
    def _tail(path, n=15):
        try:
            with open(path, errors="replace") as f:
                return "".join(f.readlines()[-n:])
        except OSError:
            return "(no log)"

    def __exit__(self, *exc):
        if self.dir is None:
            return False
        if self.env is not None:
            subprocess.run(["scancel", "--full", "-u", "root"], env=self.env, capture_output=True)
        for pid_file in ("slurmd.pid", "slurmctld.pid", "munge/munged.pid"):
            try:
                with open(os.path.join(self.dir, pid_file)) as f:
                    os.kill(int(f.read().split()[0]), signal.SIGTERM)
            except (OSError, ValueError, IndexError):
                pass
        time.sleep(1.0)
        shutil.rmtree(self.dir, ignore_errors=True)
        self.dir = None
        return False
