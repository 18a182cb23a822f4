/* lib/include/edgespace/edgespace.h — the whole public API of libedgespace.
 * Each module's header is the reference manual for that module; es_core.h
 * states the conventions they all follow. */
#ifndef EDGESPACE_EDGESPACE_H
#define EDGESPACE_EDGESPACE_H

#include "es_core.h"
#include "es_mesh.h"
#include "es_geom.h"
#include "es_io.h"
#include "es_plot.h"
#include "es_render.h"
#include "es_synth.h"
#include "es_store.h"
#include "es_ingest.h"
#include "es_stats.h"
#include "es_point.h"
#include "es_analysis.h"
#include "es_procrustes.h"
#include "es_landmarks.h"
#include "es_compare.h"
#include "es_embed.h"
#include "es_interp.h"

#endif
