/* What a run leaves behind when a signal ends it: the temporary paths it registered are
   removed and the child processes it registered (POV-Ray, with their process groups)
   terminated, on SIGINT, SIGTERM and SIGHUP; on SIGTSTP they stop with it. (A SIGKILL runs no handler: the children die by PR_SET_PDEATHSIG instead, and the
   next render sweeps the workspace; see docs/contracts.md.) */
#ifndef LENS2POV_CLEANUP_H
#define LENS2POV_CLEANUP_H

#include <pthread.h>
#include <signal.h>
#include <stdbool.h>
#include <sys/types.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Installs the handlers. Call once from main. */
void cleanup_install(void);

/* Registers and unregisters a temporary path (a file, or a folder with everything in it). */
void cleanup_track(const char *temp_path);
void cleanup_untrack(const char *temp_path);

/* Child processes to terminate (SIGTERM, then wait) before the paths are removed, and to stop
   (Ctrl-Z) and continue with us. */
void cleanup_track_child(pid_t pid);
void cleanup_untrack_child(pid_t pid);

/* A child that runs POV-Ray, or a user's wrapper of it that may not exec it, gets a process
   group of its own, so that signalling the group reaches whatever it starts: the child calls
   cleanup_child_own_group (async-signal-safe) and the parent cleanup_track_child_group, which
   also tracks it and makes this process the reaper of what the child leaves behind
   (PR_SET_CHILD_SUBREAPER), so that the rest of its group can be waited for once the child
   itself has ended. */
void cleanup_child_own_group(void);
void cleanup_track_child_group(pid_t pid);

/* Signals child pid's process group, or the child alone while it has none yet (just forked).
   Only while the child is not yet reaped: until then its number is not reused. */
int cleanup_signal_child(pid_t pid, int sig);

/* Reaps whatever of child pid's group has ended, without waiting; true once nothing of it is
   left among our children. */
bool cleanup_reap_child_group(pid_t pid);

/* Kills what is left of child pid's group and reaps it (the child too, if not yet): for a
   child that has ended, what it left running; for one that must stop now, all of it. */
void cleanup_end_child_group(pid_t pid);

/* Blocks, in the calling thread, the signals the handlers take, and gives the mask before in
   *old: for a fork that must register its child first, and for threads that must leave the
   handler to the main thread. */
void cleanup_block_signals(sigset_t *old);

/* pthread_create with those signals blocked in the new thread, so that they reach the main
   thread, whose handler stops the POV-Ray processes it tracks. */
int cleanup_start_thread(pthread_t *t, void *(*fn)(void *), void *arg);

#ifdef __cplusplus
}
#endif

#endif
