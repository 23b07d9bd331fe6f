//! Circuits, part placement and rubberbands: the inputs of the route stage.
