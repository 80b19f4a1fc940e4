"""The .fsl grammar (fsl.lark), shipped inside the wheel as package data."""
