//! Output: VTU/PVD for ParaView, CSV time histories, PNG plots.

pub mod plot;
