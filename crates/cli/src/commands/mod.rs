pub mod compare;
pub mod extract;
pub mod modes;
pub mod nlmode;
pub mod params;
pub mod reduce;
pub mod run;
pub mod timesim;
