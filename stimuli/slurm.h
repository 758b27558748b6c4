#pragma once
// `skinlab stimuli slurm|status`: a set built on a Slurm cluster. The scheduler does the distribution: one job
// array task per shard (`skinlab stimuli build --shard i/n`, each task its own process and EGL context on its
// node), then a merge job that depends on the array (afterok). Everything lives in one folder on the shared file
// system:
//   OUT/slurm/build.sbatch, merge.sbatch   the scripts of the latest submission
//   OUT/slurm/jobs.json                    every submission: shards, array job id, merge job id, the command
//   OUT/slurm/logs/build-ARRAYID_TASK.log  one log per array task (appended to when the task is requeued)
//   OUT/slurm/logs/merge-JOBID.log
//   OUT/shards/I/                          shard I's set folder (a `--shard I/N` build, resumable)
//   OUT/set/                               the merged set
#include "stimuli/build.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace skinlab::stimuli {

struct SlurmOptions {
    std::filesystem::path spec;
    std::vector<std::string> specOverrides; // --set key=value, passed on to every task
    std::filesystem::path outputDir;
    std::filesystem::path assetsDir; // empty: the tasks use $SKINLAB_ASSETS of the submitting shell
    int shards = 4;
    int jobsPerTask = 1; // `build --jobs` in each task
    std::string partition, time, account, mem;
    int gpusPerTask = 0;
    int cpusPerTask = 0;
    std::vector<std::string> sbatchArgs; // further #SBATCH lines, e.g. --qos=high, --constraint=a100
    std::optional<int> onlyShard;        // resubmit this shard alone (and a new merge job)
    // Any resubmission cancels the previous submission's merge job if it is still pending.
    bool dryRun = false;
    std::filesystem::path skinlab; // the executable the tasks run; empty: this process's own
    std::string command;           // the command line, recorded for `status`
};

// Folder layout (see above).
std::filesystem::path slurmFolder(const std::filesystem::path& out);
std::filesystem::path shardFolder(const std::filesystem::path& out, int index);
std::filesystem::path mergedSetFolder(const std::filesystem::path& out);

struct SlurmScripts {
    std::string set;
    size_t stimuli = 0; // in the whole set
    std::filesystem::path buildPath, mergePath;
    std::string build, merge;
    std::vector<int> shards; // the shards the array runs (1-based)
};

// Checks the spec (like `stimuli list`), the options and the output folder, and writes the two scripts' text.
// Throws InputError for bad input, before anything is written or submitted.
SlurmScripts slurmScripts(const SlurmOptions& options);

struct SlurmSubmission {
    SlurmScripts scripts;
    std::string arrayJob; // empty in a dry run
    std::string mergeJob;
    std::string cancelledMergeJob; // an earlier merge job still waiting, cancelled (the new submission merges)
};

// Writes the scripts into OUT/slurm and submits them with `sbatch --parsable` (the merge with
// --dependency=afterok:ARRAYID), recording the job ids in OUT/slurm/jobs.json. A dry run only returns the scripts.
// Throws RuntimeError "sbatch not found: ..." when sbatch is not on PATH, and one naming sbatch's own message when
// it refuses a script.
SlurmSubmission submitSlurm(const SlurmOptions& options);

struct ShardStatus {
    int index = 0;
    std::string state;          // done, running, pending, failed, not started, not submitted
    size_t done = 0, total = 0; // stimuli in the shard's folder / in the shard
    std::string job;            // ARRAYID_TASK of its latest submission
    std::string slurmState;     // Slurm's word (RUNNING, FAILED, TIMEOUT, ...) and exit code, when Slurm knows it
    std::filesystem::path log;  // the task's log file
    std::string lastError;      // the last "skinlab: error/failure" line of a failed task's log
};

struct SlurmStatus {
    std::string set;
    int shards = 0;
    std::vector<ShardStatus> shard;
    std::string mergeJob, mergeState; // the latest merge job and its state (done when OUT/set is complete)
    std::filesystem::path mergeLog;
    std::string resubmit;      // the recorded command, for resubmitting a failed shard
    bool slurmQueried = false; // squeue/sacct/scontrol were found and asked
};

// The state of every shard of OUT, from the shard folders and, when available, squeue, sacct and scontrol.
// Throws InputError when OUT holds no submission (no OUT/slurm/jobs.json).
SlurmStatus slurmStatus(const std::filesystem::path& out);

// Single-quotes `text` for bash.
std::string shellQuote(const std::string& text);

} // namespace skinlab::stimuli
