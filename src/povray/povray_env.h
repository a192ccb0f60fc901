/* The environment of the POV-Ray processes lens2pov starts: its own, with
   lens2pov-povray-polls.so preloaded (povray_polls.c says why). */
#ifndef LENS2POV_POVRAY_ENV_H
#define LENS2POV_POVRAY_ENV_H

/* A copy of the environment with LD_PRELOAD naming the library first (before any the user
   preloads) and LENS2POV_POLLS_PARENT our pid, or the environment unchanged when
   LENS2POV_POVRAY_POLLS is "off" or the library is found neither beside the executable nor in
   ../lib/lens2pov. NULL only when out of memory; free with povray_environment_free. */
char **povray_environment(void);
void povray_environment_free(char **env);

/* Where the library is, into path; 0 when it is not to be used. */
int povray_polls_library(char *path, unsigned long size);

#endif
