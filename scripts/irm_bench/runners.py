"""The tool runs every table is built from: generate_drive (cached by content), map_from_bag
and evaluate_map, `--jobs` at a time."""
import concurrent.futures
import hashlib
import json
import os
import subprocess
import time

import yaml


class BenchmarkError(Exception):
    """A run that failed; the message names the command and its log. `exit_code`: the
    benchmark's exit status (2: another run holds the output folder)."""

    def __init__(self, message, exit_code=1):
        super().__init__(message)
        self.exit_code = exit_code


def run(command, log):
    """Runs `command` with its output in `log`; returns (wall s, CPU s of the process)."""
    start = time.time()
    with open(log, "w") as f:
        process = subprocess.Popen(command, stdout=f, stderr=subprocess.STDOUT)
        _, status, usage = os.wait4(process.pid, 0)
        process.returncode = os.waitstatus_to_exitcode(status)
    if process.returncode != 0:
        raise BenchmarkError("failed (%d): %s\n  log: %s" % (process.returncode, " ".join(command),
                                                            log))
    return time.time() - start, usage.ru_utime + usage.ru_stime


def write_yaml(path, content):
    """Writes `content` (dicts, lists, numbers, strings) as YAML; returns the path."""
    with open(path, "w") as f:
        yaml.safe_dump(content, f, default_flow_style=None, sort_keys=False)
    return path


def load_yaml(path):
    with open(path) as f:
        return yaml.safe_load(f) or {}


def scenario_text(path):
    """The scenario's text and its `base:` chain's (the drive cache's content)."""
    with open(path) as f:
        text = f.read()
    base = (yaml.safe_load(text) or {}).get("base")
    if base:
        text += scenario_text(base if os.path.isabs(base) else
                              os.path.join(os.path.dirname(path), base))
    return text


def drive_key(bin_dir, scenario_path, seed):
    """The cache key of a generated drive: its scenario chain, the generator build, the seed."""
    digest = hashlib.sha1(scenario_text(scenario_path).encode()).hexdigest()
    key = "%s-%s" % (digest, os.path.getmtime(os.path.join(bin_dir, "generate_drive")))
    return key if seed == 1 else key + "-seed%d" % seed


def generate(bin_dir, scenario_path, out, seed=1):
    """Generates the drive into `out` unless the cached one has the same key; returns True
    when it generated."""
    key = drive_key(bin_dir, scenario_path, seed)
    stamp = os.path.join(out, ".key")
    if os.path.exists(stamp) and open(stamp).read() == key:
        return False
    os.makedirs(out, exist_ok=True)
    run([os.path.join(bin_dir, "generate_drive"), "--scenario", scenario_path, "--seed",
         str(seed), "--out", out], os.path.join(out, "generate.log"))
    with open(stamp, "w") as f:
        f.write(key)
    return True


def evaluate(bin_dir, map_path, ground_truth, metrics_path):
    """evaluate_map on one map; returns its metrics."""
    run([os.path.join(bin_dir, "evaluate_map"), "--map", map_path, "--ground-truth",
         ground_truth, "--json", metrics_path], metrics_path + ".log")
    with open(metrics_path) as f:
        return json.load(f)


def map_and_evaluate(bin_dir, drive, config_path, out):
    """Maps `drive` (drives.Drive) with one config into `out` and scores it; returns the
    metrics plus `_wall_s`, `_cpu_s` (map_from_bag's) and `_metadata` (map.json's)."""
    os.makedirs(out, exist_ok=True)
    command = [os.path.join(bin_dir, "map_from_bag"), "--bag", drive.bag, "--config",
               config_path, "--out", out]
    if drive.classes:
        command += ["--classes", drive.classes]
    wall, cpu = run(command, os.path.join(out, "map.log"))
    metrics = evaluate(bin_dir, os.path.join(out, "map.json"), drive.ground_truth,
                       os.path.join(out, "metrics.json"))
    with open(os.path.join(out, "map.json")) as f:
        metrics["_metadata"] = json.load(f).get("metadata", {})
    metrics["_wall_s"], metrics["_cpu_s"] = wall, cpu
    return metrics


class Jobs:
    """Runs independent jobs `jobs` at a time; results by key. A job may wait for the result
    of one submitted before it (jobs start in submission order)."""

    def __init__(self, jobs):
        self.pool = concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs))
        self.futures = {}

    def submit(self, key, function, *arguments):
        self.futures[key] = self.pool.submit(function, *arguments)

    def result(self, key):
        return self.futures[key].result()

    def results(self):
        return {key: future.result() for key, future in self.futures.items()}
