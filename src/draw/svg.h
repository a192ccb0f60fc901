/* The SVG around a drawing in millimetres: the document, its style, the group that maps camera
   space (z to the left toward the scene, y up) to pixels, escaped text and a scale bar. */
#ifndef LENS2POV_SVG_H
#define LENS2POV_SVG_H

#include <stdio.h>

typedef struct svg_view {
    double zmin, zmax, ymax;   /* the region drawn, mm: z in [zmin, zmax], y in [-ymax, ymax] */
    double scale;              /* pixels a millimetre */
    double margin_px;
} svg_view;

/* Pixel coordinates of camera-space z and y: the scene on the left, the film on the right. */
static inline double svg_x(const svg_view *v, double z) { return v->margin_px + (v->zmax - z) * v->scale; }
static inline double svg_y(const svg_view *v, double y) { return v->margin_px + (v->ymax - y) * v->scale; }

/* The document's head and style, and opens the group in which coordinates are z,y in mm. */
void svg_begin(FILE *out, const svg_view *v);
void svg_end_group(FILE *out);

/* A text element at pixel (x, y), XML-escaped. */
void svg_text(FILE *out, const char *class, double x, double y, const char *text);

/* A bar of a round length (1, 2 or 5 times a power of ten mm) in the bottom left corner. */
void svg_scale_bar(FILE *out, const svg_view *v);

void svg_finish(FILE *out);

#endif
