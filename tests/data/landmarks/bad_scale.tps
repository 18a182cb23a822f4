LM=1
1 2
SCALE=zero
