/* What a run leaves behind when a signal ends it: the temporary paths it registered are
   removed and the child processes it registered (POV-Ray) terminated, on SIGINT, SIGTERM and
   SIGHUP. (A SIGKILL runs no handler: the children die by PR_SET_PDEATHSIG instead, and the
   next render sweeps the workspace; see docs/contracts.md.) */
#ifndef LENS2POV_CLEANUP_H
#define LENS2POV_CLEANUP_H

#include <pthread.h>
#include <signal.h>
#include <sys/types.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Installs the handlers. Call once from main. */
void cleanup_install(void);

/* Registers and unregisters a temporary path (a file, or a folder with everything in it). */
void cleanup_track(const char *temp_path);
void cleanup_untrack(const char *temp_path);

/* Child processes to terminate (SIGTERM, then wait) before the paths are removed. */
void cleanup_track_child(pid_t pid);
void cleanup_untrack_child(pid_t pid);

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
