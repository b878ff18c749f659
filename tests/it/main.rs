//! The integration tests, one binary (wgpu and the crate link once), a module per topic; shared
//! fixtures in [`common`].

mod accelerator_axis;
mod accelerators;
mod ambient_occlusion;
mod ao_experiment;
mod axis_list;
mod bad_input;
mod blue_noise;
mod cache_keys;
mod command_line;
mod common;
mod dynamic_updates;
mod frames_experiment;
mod fuzz_config;
mod fuzz_mesh_files;
mod gpu_backend;
mod gpu_resources;
mod hard_cases;
mod hostile_input;
mod kdtree;
mod mesh_scene;
mod receiver_masks;
mod regression;
mod render_plan;
mod rim_samples;
mod sampling_properties;
mod shape_order;
mod shards;
mod summary_verdict;
mod sweep_outputs;
mod timing_phase;
mod visibility_field;
mod visibility_field_edges;
mod visibility_field_gpu;
mod visibility_field_meshes;
mod whitted;
