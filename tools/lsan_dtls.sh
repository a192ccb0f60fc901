#!/bin/sh
# Shows the LeakSanitizer fault that `make test-sanitize` avoids with
# ASAN_OPTIONS=intercept_tls_get_addr=0 (google/sanitizers#1322): threads that touch the
# thread-local variable of a dlopen()ed library get dynamic TLS blocks from malloc, some at 16
# bytes past a page boundary; GCC 12's runtime reads the ASan chunk header before such a block
# as glibc 2.19's {size, start} and the leak scan at exit crashes on that range.
# Prints one line for each setting; exit status 0 when the option avoids the crash.
set -eu
dir=$(mktemp -d /tmp/lsan_dtls.XXXXXX)
trap 'rm -rf "$dir"' EXIT
cat > "$dir/lib.c" <<'C'
__thread char block[44];
char *touch(void) { block[0] = 1; return block; }
C
cat > "$dir/main.c" <<'C'
#include <dlfcn.h>
#include <pthread.h>
#include <stdio.h>
#include <unistd.h>
static char *(*touch)(void);
static void *run(void *unused) { (void)unused; touch(); pause(); return NULL; }
int main(int argc, char **argv)
{
    (void)argc;
    void *lib = dlopen(argv[1], RTLD_NOW);
    if (!lib) { fprintf(stderr, "%s\n", dlerror()); return 3; }
    *(void **)&touch = dlsym(lib, "touch");
    for (int i = 0; i < 64; i++) {
        pthread_t t;
        pthread_create(&t, NULL, run, NULL);
        pthread_detach(t);
    }
    usleep(200000);
    return 0; /* the threads are alive when the leak scan runs */
}
C
cc -shared -fPIC -O1 "$dir/lib.c" -o "$dir/lib.so"
cc -fsanitize=address -g "$dir/main.c" -o "$dir/main" -ldl -lpthread
status() { if "$@" "$dir/main" "$dir/lib.so" 2>"$dir/err"; then echo "exit 0"; else
    echo "exit $?: $(grep -m1 'Tracer caught\|LeakSanitizer' "$dir/err" || true)"; fi; }
echo "ASAN_OPTIONS unset:                   $(status env -u ASAN_OPTIONS)"
echo "ASAN_OPTIONS=intercept_tls_get_addr=0: $(status env ASAN_OPTIONS=intercept_tls_get_addr=0)"
env ASAN_OPTIONS=intercept_tls_get_addr=0 "$dir/main" "$dir/lib.so" 2>/dev/null
