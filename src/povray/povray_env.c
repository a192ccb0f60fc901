/* The environment of the POV-Ray processes lens2pov starts. */
#include "povray/povray_env.h"

#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "base/exe_dir.h"
#include "povray/povray_cmd.h"

#define POLLS_LIBRARY "lens2pov-povray-polls.so"

extern char **environ;

int povray_polls_library(char *path, unsigned long size)
{
    const char *off = getenv("LENS2POV_POVRAY_POLLS");
    char dir[PATH_MAX];
    const char *why;
    if ((off && strcmp(off, "off") == 0) || !exe_dir(dir, sizeof dir, &why))
        return 0;
    const char *const places[2] = {"%s/" POLLS_LIBRARY, "%s/../lib/lens2pov/" POLLS_LIBRARY};
    for (int i = 0; i < 2; i++) {
        const int n = snprintf(path, size, places[i], dir);
        /* LD_PRELOAD splits its list at spaces and colons. */
        if (n > 0 && (unsigned long)n < size && !strpbrk(path, " :") && access(path, R_OK) == 0)
            return 1;
    }
    return 0;
}

static bool named(const char *entry, const char *name)
{
    const size_t n = strlen(name);
    return strncmp(entry, name, n) == 0 && entry[n] == '=';
}

char **povray_environment(void)
{
    size_t count = 0;
    while (environ[count])
        count++;
    char **env = calloc(count + 3, sizeof *env);
    if (!env)
        return NULL;
    char library[PATH_MAX + 64];
    const bool preload = povray_polls_library(library, sizeof library);
    const char *old = getenv("LD_PRELOAD");
    size_t n = 0;
    bool ok = true;
    for (size_t i = 0; i < count && ok; i++) {
        const bool replaced = named(environ[i], "LD_PRELOAD") ||
                              named(environ[i], "LENS2POV_POLLS_PARENT");
        if (preload && replaced)
            continue;
        ok = (env[n++] = strdup(environ[i])) != NULL;
    }
    if (ok && preload) {
        const bool more = old && *old;
        ok = (env[n++] = str_printf("LD_PRELOAD=%s%s%s", library, more ? ":" : "",
                                    more ? old : "")) != NULL;
        ok = ok && (env[n++] = str_printf("LENS2POV_POLLS_PARENT=%ld", (long)getpid())) != NULL;
    }
    if (!ok) {
        povray_environment_free(env);
        return NULL;
    }
    return env;
}

void povray_environment_free(char **env)
{
    for (size_t i = 0; env && env[i]; i++)
        free(env[i]);
    free(env);
}
