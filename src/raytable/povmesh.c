#include "raytable/povmesh.h"

#include <fcntl.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include "raytable/chunk_ini.h"
#include "raytable/chunk_name.h"
#include "raytable/facelist.h"
#include "base/outfile.h"
#include "raytable/povface.h"
#include "image/samplemap.h"
#include "povray/povray.h"

enum { MAX_PACKED_WIDTH = 1024, COUNT_FIELD = 20 };

typedef struct chunk {
    text_out inc;
    outfile ini;
    long count_offset;      /* where the vertex count goes, filled in at the end */
    face_list faces;
    bool committed;         /* renamed into place as soon as complete (with a hook) */
} chunk;

struct povmesh_emitter {
    const camera *cam;
    char *prefix;
    long long chunk_faces;     /* 0: one chunk */
    int packed_width;
    chunk *chunks;
    int chunk_count;
    outfile map;
    text_out csv;
    bool has_csv;
    long long faces;
    povmesh_chunk_hook hook;   /* told of each chunk as it is complete; NULL: none */
    void *hook_ctx;
    const char *placement;     /* a transform identifier applied last; NULL: none */
    char edge_text[POVMESH_RAY_TEXT_MAX];   /* the last shared edge's two vertex lines */
    size_t edge_len;
    vec3 anchor_camera_mm;     /* the front vertex: vertices are written relative to it */
    struct timespec begun;     /* when the table was begun: the map's time (commit_map) */
    double triangle_size;      /* scene units */
    int decimals;
    double decimal_scale, fixed_limit;   /* quanta per scene unit; |v| written as integers */
};

/* v in quanta of 10^-decimals scene units, as an integer rounded half away from zero; the
   mesh's scale turns quanta back into scene units. Past the range of exact integers, %.9g. */
static void put_number(text_out *t, const povmesh_emitter *e, double v)
{
    const double quanta = v * e->decimal_scale;
    if (!(fabs(v) < e->fixed_limit)) {
        t->len += (size_t)snprintf(t->buf + t->len, 32, "%.9g", quanta);
        return;
    }
    const uint64_t k = (uint64_t)(fabs(quanta) + 0.5);
    if (v < 0 && k != 0)
        t->buf[t->len++] = '-';
    text_put_uint(t, k);
}

char *povmesh_chunk_file(const char *prefix, bool chunked, int index, const char *ext)
{
    if (chunked)
        return chunk_file_name(prefix, index, ext);
    const size_t n = strlen(prefix) + strlen(ext) + 2;
    char *p = malloc(n);
    if (p)
        snprintf(p, n, "%s.%s", prefix, ext);
    return p;
}

static char *chunk_path(const povmesh_emitter *e, int index, const char *ext)
{
    return povmesh_chunk_file(e->prefix, e->chunk_faces != 0, index, ext);
}

void povmesh_set_chunk_hook(povmesh_emitter *e, povmesh_chunk_hook hook, void *ctx)
{
    e->hook = hook;
    e->hook_ctx = ctx;
}

void povmesh_set_placement(povmesh_emitter *e, const char *transform_name)
{
    e->placement = transform_name;
}

static int begin_chunk(povmesh_emitter *e, l2p_error *err)
{
    chunk *grown = realloc(e->chunks, sizeof *grown * (size_t)(e->chunk_count + 1));
    if (!grown)
        return l2p_fail(err, L2P_FAILED, e->prefix, 0, "out of memory");
    e->chunks = grown;
    chunk *ch = &e->chunks[e->chunk_count++];
    memset(ch, 0, sizeof *ch);
    char *path = chunk_path(e, e->chunk_count - 1, "inc");
    int st = path ? text_open(&ch->inc, path, err) : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    free(path);
    if (st)
        return st;
    text_out *t = &ch->inc;
    t->len += (size_t)snprintf(t->buf, 1024,
        "// lens2pov ray table: one triangle per ray for mesh_camera (distribution 0).\n"
        "// mesh_camera needs 3.7; an older scene keeps its own version (and gamma) after it.\n"
        "#if (version < 3.7)\n  #declare Lens2pov_Version = version;\n  #version 3.7;\n#end\n"
        "#declare Lens2pov_Rays = mesh2 {\n  vertex_vectors {");
    ch->count_offset = (long)t->len;
    t->len += (size_t)snprintf(t->buf + t->len, 64, "%*s,\n", COUNT_FIELD, "");
    return L2P_OK;
}

static void put_vertex(text_out *t, const povmesh_emitter *e, vec3 v)
{
    t->buf[t->len++] = '<';
    put_number(t, e, v.x);
    t->buf[t->len++] = ',';
    put_number(t, e, v.y);
    t->buf[t->len++] = ',';
    put_number(t, e, v.z);
    text_put(t, ">,\n", 3);
}

/* A ray in the mesh's frame: scene units, world axes, relative to the anchor. */
static ray mesh_ray(const povmesh_emitter *e, const ray *r)
{
    const vec3 o = camera_world_from_camera_offset(e->cam, v3_sub(r->o, e->anchor_camera_mm));
    return (ray){o, camera_world_from_camera_dir(e->cam, r->d)};
}

/* Formats face i alone, or faces i and i + 1 on a shared edge; returns the faces done. */
static int put_faces_of(const povmesh_emitter *e, const emitted_ray *r, int i, int n,
                        text_out *t, size_t *len, unsigned char *kind)
{
    const ray a = mesh_ray(e, &r[i].out);
    vec3 v[4];
    bool swap[2];
    if (i + 1 < n) {
        const ray b = mesh_ray(e, &r[i + 1].out);
        if (povface_pair(a.o, a.d, b.o, b.d, e->triangle_size, v, swap)) {
            const size_t start = t->len;
            for (int k = 0; k < 3; k++)
                put_vertex(t, e, v[k]);
            len[i] = t->len - start;
            kind[i] = (unsigned char)(FACE_GIVES_EDGE | (swap[0] ? FACE_SWAPPED : 0));
            put_vertex(t, e, v[3]);
            len[i + 1] = t->len - start - len[i];
            kind[i + 1] = (unsigned char)(FACE_SHARES_EDGE | (swap[1] ? FACE_SWAPPED : 0));
            return 2;
        }
    }
    const size_t start = t->len;
    povface_single(a.o, a.d, e->triangle_size, v);
    for (int k = 0; k < 3; k++)
        put_vertex(t, e, v[k]);
    len[i] = t->len - start;
    kind[i] = 0;
    return 1;
}

/* The camera: the mesh moved to the lens with a double-precision translate. The mesh is never
   intersected, so it gets no bounding-box tree: "hierarchy off" cuts POV-Ray's parse of the
   table by about a third and its memory by a quarter (docs/povray.md). */
static void put_camera(text_out *t, const povmesh_emitter *e)
{
    const vec3 w = camera_world_from_camera_point(e->cam, e->anchor_camera_mm);
    t->len += (size_t)snprintf(t->buf + t->len, 768,
        "  hierarchy off\n}\ncamera {\n  mesh_camera {\n    1 0\n"
        "    mesh { Lens2pov_Rays scale 1e-%d translate <%.17g, %.17g, %.17g>%s%s%s }\n  }\n}\n"
        "#undef Lens2pov_Rays\n"
        "#ifdef (Lens2pov_Version)\n  #version Lens2pov_Version;\n  #undef Lens2pov_Version\n#end\n",
        e->decimals, w.x, w.y, w.z, e->placement ? " transform { " : "",
        e->placement ? e->placement : "", e->placement ? " }" : "");
}

/* The chunk's settings, naming its render by absolute path: POV-Ray runs in the scene's
   folder, not in ours. */
static int write_ini(povmesh_emitter *e, chunk *ch, int index, long long rows, l2p_error *err)
{
    char *path = chunk_path(e, index, "ini"), *exr = chunk_path(e, index, "exr");
    const int st = path && exr ? chunk_ini_write(&ch->ini, path, exr, e->packed_width, rows + 1,
                                                         e->cam->film.width, e->cam->film.height, err)
                               : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    free(path);
    free(exr);
    return st;
}

static int end_chunk(povmesh_emitter *e, int index, l2p_error *err)
{
    chunk *ch = &e->chunks[index];
    text_out *t = &ch->inc;
    int st = text_reserve(t, 1024, err);
    if (st)
        return st;
    if (ch->faces.faces == 0) {   /* nothing passed the lens: one zero-area face, a ray to nowhere */
        text_put_str(t, "<0,0,0>,<0,0,0>,<0,0,0>,\n");
        if (face_list_add(&ch->faces, 0))
            return l2p_fail(err, L2P_FAILED, t->file.final_path, 0, "out of memory");
    }
    text_put_str(t, "  }\n");
    if ((st = face_list_write(&ch->faces, t, err)) != 0 || (st = text_reserve(t, 1024, err)) != 0)
        return st;
    text_put_str(t, "  }\n");
    put_camera(t, e);
    if ((st = text_flush(t, err)) != 0)
        return st;
    if (fseek(t->file.fp, ch->count_offset, SEEK_SET) != 0 ||
        fprintf(t->file.fp, "%*lld", COUNT_FIELD, ch->faces.vertices) != COUNT_FIELD)
        return l2p_fail(err, L2P_FAILED, t->file.final_path, 0, "write failed");
    const long long rows = (ch->faces.faces + e->packed_width - 1) / e->packed_width;
    if ((st = outfile_finish(&t->file, err)) != 0 || (st = write_ini(e, ch, index, rows, err)) != 0)
        return st;
    text_release(t);   /* a finished chunk needs neither its buffer nor its face codes */
    face_list_free(&ch->faces);
    if (!e->hook)
        return L2P_OK;
    if ((st = outfile_commit(&t->file, err)) != 0 || (st = outfile_commit(&ch->ini, err)) != 0)
        return st;
    ch->committed = true;
    return e->hook(e->hook_ctx, index) ? l2p_fail(err, L2P_FAILED, NULL, 0, "stopped") : L2P_OK;
}

/* Vertices are written as whole numbers of a quantum of about 1e-8 of the largest coordinate,
   and the mesh is scaled by the quantum: POV-Ray stores vertices as float32 (24 bits) and
   applies the scale in double, so this keeps all the precision POV-Ray can use in fewer
   characters than decimals would take. */
static void choose_number_format(povmesh_emitter *e, double largest)
{
    int p = (int)ceil(-log10(largest * 1e-8));
    e->decimals = p < 0 ? 0 : p > 17 ? 17 : p;
    e->decimal_scale = pow(10.0, e->decimals);
    e->fixed_limit = fmin(largest * 1e3, 9e15 / e->decimal_scale);
}

static void choose_layout(povmesh_emitter *e, long long chunk_faces)
{
    const camera *c = e->cam;
    const long long most = (long long)(c->crop_x1 - c->crop_x0) * (c->crop_y1 - c->crop_y0) *
                           c->samples.spp;
    e->packed_width = most < MAX_PACKED_WIDTH ? (int)(most > 0 ? most : 1) : MAX_PACKED_WIDTH;
    e->chunk_faces = 0;
    if (chunk_faces <= 0)
        return;
    /* Chunks are whole packed rows. The rows are made as wide as needed to hold the asked chunk
       size in as few rows as possible and no wider, so a chunk holds at most rows - 1 faces
       more than asked: the caller's equal shares of the faces stay equal, and their number
       stays the caller's (rounding up to rows of 1024 would turn 16 shares of 6,250 faces into
       14 chunks of 7,168). */
    const long long want = chunk_faces < most ? chunk_faces : (most > 0 ? most : 1);
    const long long rows = (want + MAX_PACKED_WIDTH - 1) / MAX_PACKED_WIDTH;
    e->packed_width = (int)((want + rows - 1) / rows);
    e->chunk_faces = rows * e->packed_width;
}

static void free_emitter(povmesh_emitter *e)
{
    for (int i = 0; i < e->chunk_count; i++) {
        text_discard(&e->chunks[i].inc);
        outfile_discard(&e->chunks[i].ini);
        face_list_free(&e->chunks[i].faces);
    }
    free(e->chunks);
    outfile_discard(&e->map);
    if (e->has_csv)
        text_discard(&e->csv);
    free(e->prefix);
    free(e);
}

static int open_side_files(povmesh_emitter *e, const char *csv_path, l2p_error *err)
{
    char *map_path = malloc(strlen(e->prefix) + 8);
    if (!map_path)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    sprintf(map_path, "%s.map", e->prefix);
    int st = outfile_open(&e->map, map_path, err);
    free(map_path);
    if (!st && samplemap_begin(e->map.fp) != 0)
        st = l2p_fail(err, L2P_FAILED, e->map.final_path, 0, "write failed");
    if (st || !csv_path)
        return st;
    e->has_csv = true;
    if ((st = text_open(&e->csv, csv_path, err)) != 0)
        return st;
    text_put_str(&e->csv, e->cam->dispersion
                              ? "raster_x,raster_y,film_x,film_y,origin_x,origin_y,origin_z,"
                                "dir_x,dir_y,dir_z,weight,wavelength_nm\n"
                              : "raster_x,raster_y,film_x,film_y,origin_x,origin_y,origin_z,"
                                "dir_x,dir_y,dir_z,weight\n");
    return L2P_OK;
}

int povmesh_open(povmesh_emitter **out, const camera *c, const char *prefix, const char *csv_path,
                 long long chunk_faces, l2p_error *err)
{
    povmesh_emitter *e = calloc(1, sizeof *e);
    if (!e || !(e->prefix = strdup(prefix))) {
        free(e);
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    }
    e->cam = c;
    clock_gettime(CLOCK_REALTIME, &e->begun);
    e->anchor_camera_mm = v3(0, 0, c->lens.surface[0].vertex_z_mm);
    double widest = 0.0;
    for (int i = 0; i < c->lens.count; i++)
        widest = fmax(widest, c->lens.surface[i].aperture_diameter_mm);
    e->triangle_size = 0.5 * widest / c->unit_mm;
    choose_number_format(e, 4.0 * e->triangle_size);
    choose_layout(e, chunk_faces);
    int st = open_side_files(e, csv_path, err);
    if (!st)
        st = begin_chunk(e, err);
    if (st) {
        free_emitter(e);
        return st;
    }
    *out = e;
    return L2P_OK;
}

bool povmesh_wants_csv(const povmesh_emitter *e) { return e->has_csv; }

/* A row of the CSV; the wavelength column only with dispersion. */
static size_t put_csv(char *csv, const emitted_ray *r, bool dispersion)
{
    int n = snprintf(csv, POVMESH_CSV_MAX,
        "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g",
        r->px + r->offset_x, r->py + r->offset_y, r->film_point.x, r->film_point.y,
        r->out.o.x, r->out.o.y, r->out.o.z, r->out.d.x, r->out.d.y, r->out.d.z, r->weight);
    if (dispersion)
        n += snprintf(csv + n, POVMESH_CSV_MAX - (size_t)n, ",%.17g", r->wavelength_nm);
    n += snprintf(csv + n, POVMESH_CSV_MAX - (size_t)n, "\n");
    return (size_t)n;
}

void povmesh_format_rays(const povmesh_emitter *e, const emitted_ray *r, int n,
                         formatted_faces *f)
{
    text_out t = {.buf = f->text, .len = f->text_len};
    size_t *len = f->length + f->count;
    unsigned char *kind = f->kind + f->count;
    for (int i = 0; i < n;)
        i += put_faces_of(e, r, i, n, &t, len, kind);
    f->text_len = t.len;
    for (int i = 0; i < n; i++, f->count++) {
        f->record[f->count] = (samplemap_record){
            (uint32_t)r[i].py * (uint32_t)e->cam->film.width + (uint32_t)r[i].px,
            (float)r[i].offset_x, (float)r[i].offset_y, (float)r[i].weight};
        f->band[f->count] = (uint32_t)r[i].band;
        if (e->has_csv) {
            f->csv_length[f->count] = put_csv(f->csv + f->csv_len, &r[i], e->cam->dispersion);
            f->csv_len += f->csv_length[f->count];
        }
    }
}

/* The vertex text of one face, and its code. A face that shares the edge of a face left in
   the previous chunk gets the edge's vertices again. */
static int put_face(povmesh_emitter *e, chunk *ch, const char *text, size_t len, unsigned kind,
                    l2p_error *err)
{
    const bool shares = kind & FACE_SHARES_EDGE, alone = shares && ch->faces.faces == 0;
    int st = text_reserve(&ch->inc, len + (alone ? e->edge_len : 0), err);
    if (st)
        return st;
    if (kind & FACE_GIVES_EDGE) {   /* its first two lines are the edge */
        const char *end = memchr(text, '\n', len);
        end = end ? memchr(end + 1, '\n', len - (size_t)(end + 1 - text)) : NULL;
        e->edge_len = end ? (size_t)(end + 1 - text) : 0;
        memcpy(e->edge_text, text, e->edge_len);
    }
    if (alone)
        text_put(&ch->inc, e->edge_text, e->edge_len);
    text_put(&ch->inc, text, len);
    /* A face whose edge went with the chunk before has its vertices of its own. */
    if (face_list_add(&ch->faces, alone ? kind & ~(unsigned)FACE_SHARES_EDGE : kind))
        return l2p_fail(err, L2P_FAILED, ch->inc.file.final_path, 0, "out of memory");
    return L2P_OK;
}

static int append_face(povmesh_emitter *e, const char *text, size_t len, unsigned kind,
                       const samplemap_record *rec, const uint32_t *band, const char *csv,
                       size_t csv_len, l2p_error *err)
{
    int st;
    chunk *ch = &e->chunks[e->chunk_count - 1];
    if (e->chunk_faces && ch->faces.faces == e->chunk_faces) {
        if ((st = end_chunk(e, e->chunk_count - 1, err)) || (st = begin_chunk(e, err)))
            return st;
        ch = &e->chunks[e->chunk_count - 1];
    }
    if ((st = put_face(e, ch, text, len, kind, err)) != 0)
        return st;
    e->faces++;
    if (samplemap_append(e->map.fp, rec, e->cam->dispersion ? band : NULL, 1) != 0)
        return l2p_fail(err, L2P_FAILED, e->map.final_path, 0, "write failed");
    if (!e->has_csv)
        return L2P_OK;
    if ((st = text_reserve(&e->csv, csv_len, err)) != 0)
        return st;
    text_put(&e->csv, csv, csv_len);
    return L2P_OK;
}

int povmesh_append(povmesh_emitter *e, const formatted_faces *f, l2p_error *err)
{
    size_t at = 0, csv_at = 0;
    for (long long i = 0; i < f->count; i++) {
        const size_t csv_len = e->has_csv ? f->csv_length[i] : 0;
        int st = append_face(e, f->text + at, f->length[i], f->kind[i], &f->record[i],
                             &f->band[i], f->csv + csv_at, csv_len, err);
        if (st)
            return st;
        at += f->length[i];
        csv_at += csv_len;
    }
    return L2P_OK;
}

void povmesh_camera_header(const camera *c, samplemap_header *h)
{
    memset(h, 0, sizeof *h);
    h->film_width = c->film.width;
    h->film_height = c->film.height;
    h->spp = c->samples.spp;
    h->crop_x0 = c->crop_x0;
    h->crop_y0 = c->crop_y0;
    h->crop_x1 = c->crop_x1;
    h->crop_y1 = c->crop_y1;
    snprintf(h->lens, sizeof h->lens, "%s", c->lens.name ? c->lens.name : "");
    snprintf(h->pupil, sizeof h->pupil, "%s", pupil_kind_name(c->pupil.kind));
    snprintf(h->trace, sizeof h->trace, "%s", c->trace == TRACE_KIND_THICK ? "thick" : "full");
    snprintf(h->weighting, sizeof h->weighting, "%s",
             c->weighting == WEIGHTING_PHYSICAL ? "physical" : "normalized");
    h->f_number = c->f_number;
    h->aperture_diameter_mm = c->lens.stop_diameter_mm;
    h->focus_distance_units = c->focus_distance_units;
    h->film_distance_mm = c->lens.film_distance_mm;
    h->film_diagonal_mm = c->film.diagonal_mm;
    h->unit_mm = c->unit_mm;
    h->wavelength_bands = c->dispersion ? c->samples.spp : 0;
}

static void fill_map_header(const povmesh_emitter *e, samplemap_header *h)
{
    povmesh_camera_header(e->cam, h);
    h->packed_width = e->packed_width;
    h->faces = e->faces;
    const long long one = e->faces > 0 ? e->faces : 1;
    h->chunk_faces = e->chunk_faces ? e->chunk_faces
                                    : (one + e->packed_width - 1) / e->packed_width * e->packed_width;
}

static int finish_all(povmesh_emitter *e, l2p_error *err)
{
    int st = end_chunk(e, e->chunk_count - 1, err);
    samplemap_header h;
    fill_map_header(e, &h);
    if (!st && samplemap_finish(e->map.fp, &h) != 0)
        st = l2p_fail(err, L2P_FAILED, e->map.final_path, 0, "write failed");
    if (!st && e->has_csv && !(st = text_flush(&e->csv, err)))
        st = outfile_finish(&e->csv.file, err);
    if (!st)
        st = outfile_finish(&e->map, err);
    return st;
}

/* A target that turned into a folder during the run cannot be renamed onto: found before
   the first rename, so that the set is replaced whole or not at all. */
static int check_target(const outfile *f, l2p_error *err)
{
    struct stat sb;
    if (f->temp_path && stat(f->final_path, &sb) == 0 && S_ISDIR(sb.st_mode))
        return l2p_fail(err, L2P_FAILED, f->final_path, 0, "cannot write: Is a directory");
    return L2P_OK;
}

/* The map is renamed into place last, after chunks that render may have rendered already: it
   takes the time the table was begun, so that develop finds every render of this trace newer
   than its map, and one of an earlier trace older (develop_command.c, warn_older). */
static int commit_map(povmesh_emitter *e, l2p_error *err)
{
    char *path = strdup(e->map.final_path);
    int st = path ? outfile_commit(&e->map, err) : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    const struct timespec times[2] = {e->begun, e->begun};
    if (!st)   /* in place already: a time that cannot be set costs only develop's check */
        (void)utimensat(AT_FDCWD, path, times, 0);
    free(path);
    return st;
}

static int commit_all(povmesh_emitter *e, l2p_error *err)
{
    int st = check_target(&e->map, err);
    if (!st && e->has_csv)
        st = check_target(&e->csv.file, err);
    for (int i = 0; i < e->chunk_count && !st; i++)
        if (!e->chunks[i].committed && !(st = check_target(&e->chunks[i].inc.file, err)))
            st = check_target(&e->chunks[i].ini, err);
    for (int i = 0; i < e->chunk_count && !st; i++)
        if (!e->chunks[i].committed && !(st = outfile_commit(&e->chunks[i].inc.file, err)))
            st = outfile_commit(&e->chunks[i].ini, err);
    if (!st && e->has_csv)
        st = outfile_commit(&e->csv.file, err);
    return st ? st : commit_map(e, err);
}

int povmesh_close(povmesh_emitter *e, bool commit, int *chunk_count, l2p_error *err)
{
    int st = L2P_OK;
    if (commit && !(st = finish_all(e, err)) && !(st = commit_all(e, err)) && chunk_count)
        *chunk_count = e->chunk_count;
    free_emitter(e);
    return st;
}
