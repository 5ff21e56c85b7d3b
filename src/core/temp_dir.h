// core/temp_dir.h — private working folders beside an output, and the
// removal of those a killed run left.
// Owns: makeWorkFolder.
// Why: the --video step makes a folder of links and ffmpeg's output beside
// the video. SIGINT/SIGTERM remove it (cli/animation_command), but SIGKILL
// cannot be caught, and nothing removed the folder later (issue 27 item 13).
// The folder's name carries the owning process id, so a later run can tell
// a dead run's folder from a live one's, as core/atomic_file does for its
// temporaries: only entries named exactly "<prefix><pid>-XXXXXX" (six
// mkdtemp characters), that are directories (not links), whose process is
// gone (kill(pid, 0) fails with ESRCH), are removed. PIDs are this
// machine's (docs/output-safety.md).
#pragma once
#include <string>

namespace tdpm {

// Removes stale "<prefix><pid>-XXXXXX" folders of dead processes in `dir`
// ("" = the current directory), then creates "<dir>/<prefix><ownpid>-XXXXXX"
// (mkdtemp, mode 0700) and returns its path. `prefix` must start with '.'
// and contain no '/'. Throws tdpm::Error naming `what` and the directory on
// failure.
std::string makeWorkFolder(const std::string& dir, const std::string& prefix, const std::string& what);

// Only the stale-folder removal (tests; makeWorkFolder calls it). Returns
// how many folders were removed.
int removeStaleWorkFolders(const std::string& dir, const std::string& prefix);

}  // namespace tdpm
