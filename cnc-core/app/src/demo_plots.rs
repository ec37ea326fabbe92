//! The plots of `cnc demo`: one SVG per station, drawn from the trace file the run wrote with
//! [`crate::plot`] (what `cnc plot --signals ...` draws from `demo.csv`).

use crate::plot::{Figure, PlotError, Series, Table, Unit};
use std::path::Path;

/// A plot: file name, title, and its curves as (trace column, legend, unit).
type PlotSpec = (
    &'static str,
    &'static str,
    &'static [(&'static str, &'static str, &'static str)],
);

const PLOTS: &[PlotSpec] = &[
    (
        "robots.svg",
        "example 3: the master carries the workpiece, the slaves follow (world X and Z)",
        &[
            ("gpCh[0]^bahn_state.coord_r[0].w0_position_r", "master X", "mm"),
            ("gpCh[1]^bahn_state.coord_r[0].w0_position_r", "slave-left X", "mm"),
            ("gpCh[2]^bahn_state.coord_r[0].w0_position_r", "slave-right X", "mm"),
            ("gpCh[0]^bahn_state.coord_r[2].w0_position_r", "master Z", "mm"),
            ("gpCh[1]^bahn_state.coord_r[2].w0_position_r", "slave-left Z", "mm"),
            ("gpCh[2]^bahn_state.coord_r[2].w0_position_r", "slave-right Z", "mm"),
        ],
    ),
    (
        "tracking.svg",
        "dynamic-CS state per channel (0 inactive, 1 activating, 2 active, 3 deactivating)",
        &[
            ("gpCh[1]^channel_mc_control.dyn_cs.state_r.actual_state", "slave-left", "raw"),
            ("gpCh[2]^channel_mc_control.dyn_cs.state_r.actual_state", "slave-right", "raw"),
            ("gpCh[3]^channel_mc_control.dyn_cs.state_r.actual_state", "turntable", "raw"),
        ],
    ),
    (
        "turntable.svg",
        "example 4: table angle; the tool in the machine CS after the dynamic CS (the table turned -90 degree: the program's X moves show in Y)",
        &[
            ("gpAx[24]^lr_state.current_position_acs_r", "table X1", "deg"),
            ("gpCh[3]^bahn_state.coord_r[0].position_dyncs_r", "tool X", "mm"),
            ("gpCh[3]^bahn_state.coord_r[1].position_dyncs_r", "tool Y", "mm"),
        ],
    ),
    (
        "cam.svg",
        "cam station: conveyor angle and the lifter it drives",
        &[
            ("gpAx[25]^lr_state.command_position_acs_r", "conveyor", "deg"),
            ("gpAx[26]^lr_state.command_position_acs_r", "lifter", "mm"),
        ],
    ),
    (
        "saw.svg",
        "flying saw: material conveyor, saw carriage and blade",
        &[
            ("gpAx[27]^lr_state.command_position_acs_r", "conveyor", "mm"),
            ("gpAx[28]^lr_state.command_position_acs_r", "saw", "mm"),
            ("gpAx[29]^lr_state.command_position_acs_r", "blade", "mm"),
        ],
    ),
];

/// Draws every plot of the demo's trace file `csv` into `dir`; returns the file names.
pub fn draw(csv: &Path, dir: &Path) -> Result<Vec<String>, PlotError> {
    let table = Table::read(csv)?;
    let time = table.column("time")?;
    let mut files = Vec::with_capacity(PLOTS.len());
    for (file, title, curves) in PLOTS {
        let mut series = Vec::with_capacity(curves.len());
        for (column, legend, unit) in *curves {
            series.push(Series {
                name: (*legend).to_string(),
                unit: Unit::named(unit)?,
                points: time.iter().copied().zip(table.column(column)?).collect(),
            });
        }
        let figure = Figure {
            title: (*title).to_string(),
            x_label: "time [s]".into(),
            series,
        };
        figure.save_svg(&dir.join(file))?;
        files.push((*file).to_string());
    }
    Ok(files)
}
