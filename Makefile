# lens2pov: `make` builds build/lens2pov; `make test` runs every test; `make demo` renders the
# bundled scene. Every build and test target first runs `deps`, which installs the Debian packages
# that are missing (and does nothing when all are present).

CC       ?= cc
CXX      ?= c++
PREFIX   ?= /usr/local
BUILD    ?= build
OPT      ?= -O2
# -ffp-contract=off: a fused multiply-add rounds once where the code says round twice; the
# vector lanes and the one-ray kernel agree bit for bit only without it (GCC's gnu11 mode and
# clang contract by default).
C_DIALECT     = -std=c11 -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE -fno-math-errno -ffp-contract=off
CFLAGS_BASE   = $(C_DIALECT) $(OPT) -g -Wall -Wextra -Werror -Isrc
# The sanitizers of make test-sanitize and of the fuzz targets.
SANITIZERS    = -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
CXXFLAGS_BASE = -std=c++17 $(OPT) -g -Wall -Wextra -Werror -Isrc
SAN      ?=
LDLIBS   = -lm -lpthread -ldl
OIIO_CFLAGS = $(shell pkg-config --cflags OpenImageIO 2>/dev/null)
OIIO_LIBS   = $(shell pkg-config --libs OpenImageIO 2>/dev/null || echo -lOpenImageIO -lOpenImageIO_Util)
# OpenImageIO is not linked into the executables: src/image/image_io.cpp alone becomes
# lens2pov-image-io.so beside them, which src/image/image_io_loader.c dlopen()s on the first image read
# or write (`info` and `trace` never load it). The library calls back into the executable for
# these five functions, so every executable that may load it exports them.
IMAGE_IO_SO    = $(BUILD)/lens2pov-image-io.so
# src/povray/povray_polls.c alone becomes lens2pov-povray-polls.so beside them, which the POV-Ray
# processes lens2pov starts preload (src/povray/povray_env.c): never with the sanitizers, since
# POV-Ray has no sanitizer runtime, and not in liblens2pov, whose programs keep their own waits.
POLLS_SO       = $(BUILD)/lens2pov-povray-polls.so
IMAGE_IO_HOST  = -Wl,--export-dynamic-symbol=l2p_fail -Wl,--export-dynamic-symbol=cleanup_track \
                 -Wl,--export-dynamic-symbol=cleanup_untrack \
                 -Wl,--export-dynamic-symbol=outfile_create_temp \
                 -Wl,--export-dynamic-symbol=outfile_target

DEB_PACKAGES = povray povray-includes libopenimageio-dev openimageio-tools libcriterion-dev \
               pkg-config g++ gnuplot-nox valgrind clang libclang-rt-14-dev fonts-dejavu-core libxml2-utils \
               time

# The sources, one folder per stage of the data flow (docs/source.md).
LIB_C   = $(filter-out src/cli/main.c src/povray/povray_polls.c,$(wildcard src/*/*.c))
LIB_OBJ = $(LIB_C:src/%.c=$(BUILD)/obj/%.o)
TEST_C  = $(wildcard tests/*.c)
TEST_OBJ = $(TEST_C:tests/%.c=$(BUILD)/tobj/%.o)

.PHONY: all deps test test-unit test-sanitize test-extra bench bench-field-error demo gallery report \
        report-field report-default-film stability fuzz valgrind install clean

all: $(BUILD)/lens2pov

deps:
	@sh tools/deps.sh $(DEB_PACKAGES)

# -MMD -MP: each object also writes the headers it includes (a .d file beside it), so that a
# changed header rebuilds exactly the objects that include it; a changed Makefile rebuilds all.
$(BUILD)/obj/%.o: src/%.c Makefile
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_BASE) $(SAN) $(CFLAGS) -MMD -MP -c $< -o $@

comma := ,
# The lane tracers (src/optics/trace_lanes_*.c) are loops over lanes, worth having only when
# vectorized: they are built at -O2 in every build, and in a sanitizer build with
# UndefinedBehaviorSanitizer but not AddressSanitizer, whose check of each lane's loads and
# stores keeps the loops scalar (at the sanitizer build's -O1, with ASan, they were 50 times
# slower than in the release build, most of the sanitizer suite's time).
# Their arithmetic is the one-ray tracer's text (trace_kernel.h), which ASan checks, and their
# memory a trace_batch's fixed arrays, which checked code fills.
$(BUILD)/obj/optics/trace_lanes_%.o: src/optics/trace_lanes_%.c Makefile
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_BASE) -O2 $(subst -fsanitize=address$(comma),-fsanitize=,$(SAN)) $(CFLAGS) -MMD -MP -c $< -o $@

# The only C++ (src/image/image_io.cpp) goes into the shared library only, hence -fPIC.
$(BUILD)/obj/%.o: src/%.cpp Makefile
	@mkdir -p $(@D)
	$(CXX) $(CXXFLAGS_BASE) $(SAN) $(CXXFLAGS) -fPIC $(OIIO_CFLAGS) -MMD -MP -c $< -o $@

$(BUILD)/tobj/%.o: tests/%.c Makefile | $(BUILD)/tobj
	$(CC) $(CFLAGS_BASE) $(SAN) $(CFLAGS) -DLENS2POV_SOURCE_DIR='"$(CURDIR)"' -MMD -MP -c $< -o $@

$(BUILD)/liblens2pov.a: $(LIB_OBJ)
	rm -f $@ && ar rcs $@ $^

$(IMAGE_IO_SO): $(BUILD)/obj/image/image_io.o
	$(CXX) $(SAN) -shared $^ -o $@ $(OIIO_LIBS)

$(POLLS_SO): src/povray/povray_polls.c Makefile
	@mkdir -p $(@D)
	$(CC) $(C_DIALECT) -O2 -Wall -Wextra -Werror -fPIC -shared $< -o $@ -ldl

# Order-only: the libraries are loaded at run time, a new one needs no relink.
$(BUILD)/lens2pov: $(BUILD)/obj/cli/main.o $(BUILD)/liblens2pov.a | $(IMAGE_IO_SO) $(POLLS_SO)
	$(CC) $(SAN) $(IMAGE_IO_HOST) $^ -o $@ $(LDLIBS)

$(BUILD)/run_tests: $(TEST_OBJ) $(BUILD)/liblens2pov.a | $(IMAGE_IO_SO) $(POLLS_SO)
	$(CC) $(SAN) $(IMAGE_IO_HOST) $^ -o $@ -lcriterion $(LDLIBS)

$(BUILD)/tobj:
	mkdir -p $@

-include $(wildcard $(BUILD)/obj/*/*.d $(BUILD)/tobj/*.d)

# The test suite runs the built binary too, so it needs both.
test-unit: $(BUILD)/lens2pov $(BUILD)/run_tests
	LENS2POV=$(CURDIR)/$(BUILD)/lens2pov $(BUILD)/run_tests $(TEST_ARGS)

test: deps
	$(MAKE) test-unit
	$(MAKE) test-sanitize
	$(MAKE) test-extra

# Checks beyond the Criterion suite: a short fuzz run of the lens reader, the option parser and
# the scene-camera reader, and valgrind over info, trace, a bad lens, develop and a render
# (tools/valgrind.sh).
test-extra: fuzz valgrind

# The same suite under AddressSanitizer and UndefinedBehaviorSanitizer, in its own build folder.
# intercept_tls_get_addr=0: GCC 12's runtime takes a dynamic TLS block at 16 bytes past a page
# boundary for glibc 2.19's layout and reads the 16 bytes before it as the block's start and size;
# under ASan those bytes are the heap chunk's header, and the leak scan at exit crashes on the
# range they make (google/sanitizers#1322). glibc allocates those blocks with malloc and points
# to them from the thread's DTV, so the leak scan still reaches them without the interceptor.
test-sanitize: deps
	@if grep -n '\.timeout *=' tests/*.c; then echo "tests: no .timeout: Criterion's runner then \
	leaks under AddressSanitizer (tests/test_povray.c)" >&2; exit 1; fi
	ASAN_OPTIONS=intercept_tls_get_addr=0$${ASAN_OPTIONS:+:$$ASAN_OPTIONS} \
	$(MAKE) BUILD=build-san OPT=-O1 \
	  SAN='$(SANITIZERS)' \
	  TEST_ARGS='$(TEST_ARGS) --jobs 2' test-unit

bench: deps $(BUILD)/lens2pov $(BUILD)/bench_trace
	sh tools/bench.sh $(BUILD)

# Ray fields' error against time on the four standard lenses (tools/bench_field_error.sh),
# uniform and with --adaptive (the references are shared): longer than the rest of make bench,
# so a target of its own.
bench-field-error: deps $(BUILD)/lens2pov
	sh tools/bench_field_error.sh $(BUILD)
	FIELD_OPTS=--adaptive sh tools/bench_field_error.sh $(BUILD)

$(BUILD)/bench_trace: tools/bench_trace.c $(BUILD)/liblens2pov.a
	$(CC) $(CFLAGS_BASE) $^ -o $@ $(LDLIBS)

demo: deps $(BUILD)/lens2pov
	sh tools/demo.sh $(BUILD)/lens2pov

gallery: deps $(BUILD)/lens2pov
	sh examples/render-all-lenses.sh pov/scene.pov out/gallery

report: deps $(BUILD)/lens2pov
	sh tools/report.sh $(BUILD)

# The report's last two parts alone: pixel against field sampling at the report's film
# (tools/report_field.sh) and at render's default film and spp (tools/report_default_film.sh).
report-field: deps $(BUILD)/lens2pov
	sh tools/report_field.sh $(BUILD)

report-default-film: deps $(BUILD)/lens2pov
	sh tools/report_default_film.sh $(BUILD)

stability: deps $(BUILD)/lens2pov
	sh tools/stability.sh $(BUILD)

fuzz: deps
	FUZZ_CFLAGS='$(C_DIALECT) -g -O1' FUZZ_SANITIZERS='$(SANITIZERS)' sh tests/fuzz/run.sh

valgrind: deps $(BUILD)/lens2pov
	sh tools/valgrind.sh $(BUILD)/lens2pov

# The image library goes to PREFIX/lib/lens2pov/, where lens2pov looks for it (../lib/lens2pov
# from its own folder) when it is not beside it.
# The batch script goes beside it as lens2pov-render-all, the man page to share/man/man1, the
# user's guide and docs to share/doc/lens2pov.
install: $(BUILD)/lens2pov
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib/lens2pov \
	  $(DESTDIR)$(PREFIX)/share/lens2pov/lenses $(DESTDIR)$(PREFIX)/share/lens2pov/pov \
	  $(DESTDIR)$(PREFIX)/share/man/man1 $(DESTDIR)$(PREFIX)/share/doc/lens2pov/docs \
	  $(DESTDIR)$(PREFIX)/share/doc/lens2pov/examples
	install -m 755 $(BUILD)/lens2pov $(DESTDIR)$(PREFIX)/bin/lens2pov
	install -m 755 examples/render-all-lenses.sh $(DESTDIR)$(PREFIX)/bin/lens2pov-render-all
	install -m 644 docs/lens2pov.1 $(DESTDIR)$(PREFIX)/share/man/man1/lens2pov.1
	install -m 644 README.md $(DESTDIR)$(PREFIX)/share/doc/lens2pov
	install -m 644 examples/README.md $(DESTDIR)$(PREFIX)/share/doc/lens2pov/examples
	install -m 644 docs/*.md docs/*.png docs/*.svg $(DESTDIR)$(PREFIX)/share/doc/lens2pov/docs
	install -m 644 $(IMAGE_IO_SO) $(DESTDIR)$(PREFIX)/lib/lens2pov/lens2pov-image-io.so
	install -m 644 $(POLLS_SO) $(DESTDIR)$(PREFIX)/lib/lens2pov/lens2pov-povray-polls.so
	install -m 644 lenses/*.dat $(DESTDIR)$(PREFIX)/share/lens2pov/lenses
	install -m 644 pov/* $(DESTDIR)$(PREFIX)/share/lens2pov/pov

clean:
	rm -rf build build-san build-fuzz out/tmp
