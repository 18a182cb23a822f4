/* tools/commands.h — the subcommands, each in tools/cmd/<verb>.c. */
#ifndef EDGESPACE_TOOLS_COMMANDS_H
#define EDGESPACE_TOOLS_COMMANDS_H

/* -- topology, geometry, synthetic data */
int cmd_synth(int argc, char **argv);
/* -- mesh I/O */
/* -- store, manifest, ingest */
int cmd_ingest(int argc, char **argv);
int cmd_info(int argc, char **argv);
int cmd_export(int argc, char **argv);
int cmd_results(int argc, char **argv);
/* -- statistics, point syntax */
int cmd_mean(int argc, char **argv);
int cmd_pca(int argc, char **argv);
int cmd_diff(int argc, char **argv);
int cmd_project(int argc, char **argv);
int cmd_point(int argc, char **argv);
int cmd_plot_pca(int argc, char **argv);
int cmd_model(int argc, char **argv);
/* -- procrustes, landmarks, comparison */
int cmd_gpa(int argc, char **argv);
int cmd_compare(int argc, char **argv);
int cmd_ingest_landmarks(int argc, char **argv);
/* -- embedding, interpolation */
int cmd_embed(int argc, char **argv);
int cmd_interp(int argc, char **argv);
int cmd_explore(int argc, char **argv);
/* -- plotting, rendering */
int cmd_render(int argc, char **argv);
int cmd_plot(int argc, char **argv);
int cmd_variation(int argc, char **argv);

#endif
