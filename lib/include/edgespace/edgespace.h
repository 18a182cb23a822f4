/* lib/include/edgespace/edgespace.h — the whole public API of libedgespace,
 * in the order of the data flow (lib/README.md). Each module's header is the
 * reference manual for that module; es_core.h states the conventions they
 * all follow. es_config.h says whether this build has figures. */
#ifndef EDGESPACE_EDGESPACE_H
#define EDGESPACE_EDGESPACE_H

#include "es_config.h"
#include "es_core.h"        /* core */
#include "es_parallel.h"    /* parallel */
#include "es_mesh.h"        /* mesh */
#include "es_geom.h"
#include "es_io.h"          /* meshio */
#include "es_store.h"       /* store */
#include "es_ingest.h"      /* ingest */
#include "es_landmarks.h"
#include "es_stats.h"       /* stats */
#include "es_point.h"
#include "es_model.h"
#include "es_procrustes.h"  /* procrustes */
#include "es_compare.h"
#include "es_embed.h"       /* embed */
#include "es_interp.h"
#include "es_morph.h"        /* morph */
#include "es_study.h"       /* study */
#include "es_synth.h"       /* synth */
#if ES_HAVE_FIGURES
#include "es_plot.h"        /* figure */
#include "es_render.h"
#include "es_figure.h"
#endif

#endif
